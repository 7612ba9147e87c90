#!/usr/bin/env python3
"""Doxygen input filter: reads orbis's plain `//` comments as documentation.

The headers document their declarations with ordinary `//` comments (the project's style), and
open with a contract comment. Doxygen only reads `///`-style comments, so this filter rewrites,
on the fly and without changing line numbers:
  - the file's opening comment block into the file's documentation (`/// @file`);
  - a `//` comment block that directly precedes a declaration at namespace or class scope into a
    `///` block (comments inside function bodies are left alone);
  - a trailing `// ...` after a declaration at namespace or class scope into `///< ...`;
  - `// @{` and `// @}` around a run of members into a Doxygen member group, whose first
    member's comment documents them all (DISTRIBUTE_GROUP_DOC).
Characters Doxygen would read as commands or HTML (`\\ @ < > & # %`) are escaped outside `code`
spans, so a comment reads as written. Usage (Doxygen's INPUT_FILTER): doxygen_filter.py FILE
"""
import re
import sys

SCOPE_HEAD = re.compile(r'\b(namespace|class|struct|union|enum)\b|extern\s+"C"')
ESCAPE = re.compile(r'([\\@<>&#%$])')


def escape_text(text):
    """Escapes Doxygen's command and HTML characters outside `code` spans."""
    parts = text.split('`')
    for i in range(0, len(parts), 2):
        parts[i] = ESCAPE.sub(r'\\\1', parts[i])
    return '`'.join(parts)


def split_code_comment(line):
    """Returns (code, comment) where comment is the text after a `//` outside strings, or None."""
    i, n, quote = 0, len(line), None
    while i < n:
        c = line[i]
        if quote:
            if c == '\\':
                i += 2
                continue
            if c == quote:
                quote = None
        elif c in '"\'':
            # a digit separator (1'000) is not a character literal
            if c == "'" and i > 0 and line[i - 1].isalnum() and i + 1 < n and line[i + 1].isalnum():
                pass
            else:
                quote = c
        elif line.startswith('//', i):
            return line[:i], line[i:]
        elif line.startswith('/*', i):
            end = line.find('*/', i + 2)
            if end < 0:
                return line[:i], None
            i = end + 2
            continue
        i += 1
    return line, None


def is_comment_line(line):
    s = line.strip()
    return (s.startswith('//') and not s.startswith('///') and not s.startswith('//!')
            and s not in ('// @{', '// @}'))


def filter_lines(lines, path):
    out = list(lines)
    stack = []          # True = namespace/class scope, False = a body ({...} of a function, lambda, ...)
    head = ''           # code since the last ; { or } (the head of the next brace)
    in_block_comment = False
    started = False     # past the file's opening comment block
    n = len(lines)
    i = 0
    while i < n:
        line = lines[i]
        stripped = line.strip()
        if not started:
            if is_comment_line(line):
                # the opening contract comment documents the file: "/// @file PATH first line"
                j = i
                while j < n and is_comment_line(lines[j]):
                    j += 1
                for k in range(i, j):
                    text = escape_text(lines[k].lstrip()[2:].rstrip('\n'))
                    out[k] = ('/// @file ' + path + ' ' + text.lstrip() if k == i else '///' + text) + '\n'
                started = True
                i = j
                continue
            if stripped:
                started = True
        at_scope = all(stack)
        if stripped in ('// @{', '// @}') and at_scope:
            # a member group: the first member's documentation covers every member up to "// @}"
            out[i] = line.replace('// @', '///@', 1)
            i += 1
            continue
        if is_comment_line(line) and not in_block_comment and stripped.startswith(('// ---', '// ===')):
            i += 1  # a section rule ("// ---- the atlas ----") titles what follows; it documents nothing
            continue
        if is_comment_line(line) and not in_block_comment:
            j = i
            while j < n and is_comment_line(lines[j]):
                j += 1
            nxt = lines[j].strip() if j < n else ''
            attach = (at_scope and nxt and not nxt.startswith('#') and not nxt.startswith('}')
                      and not re.match(r'(public|private|protected)\s*:', nxt))
            if attach:
                for k in range(i, j):
                    indent = lines[k][:len(lines[k]) - len(lines[k].lstrip())]
                    out[k] = indent + '///' + escape_text(lines[k].lstrip()[2:].rstrip('\n')) + '\n'
            i = j
            continue
        code, comment = split_code_comment(line.rstrip('\n'))
        if in_block_comment:
            end = line.find('*/')
            if end < 0:
                i += 1
                continue
            in_block_comment = False
            code, comment = split_code_comment(line[end + 2:].rstrip('\n'))
        if code.strip().startswith('#'):
            i += 1
            continue
        # block comments opening on this line
        if '/*' in code and '*/' not in code[code.index('/*'):]:
            in_block_comment = True
            code = code[:code.index('/*')]
        if comment is not None and not comment.startswith('///') and at_scope:
            body = code.rstrip()
            if body.endswith((';', ',')) and stack:
                out[i] = code + '///<' + escape_text(comment[2:]) + '\n'
        # braces, outside strings
        for c in re.sub(r'"(\\.|[^"\\])*"|\'(\\.|[^\'\\])\'', '""', code):
            if c == '{':
                stack.append(bool(SCOPE_HEAD.search(head)) and '(' not in head.split('{')[-1].split('=')[0][-1:])
                head = ''
            elif c == '}':
                if stack:
                    stack.pop()
                head = ''
            elif c == ';':
                head = ''
            else:
                head += c
        head += ' '
        i += 1
    return out


def main():
    with open(sys.argv[1], encoding='utf-8') as f:
        lines = f.readlines()
    sys.stdout.write(''.join(filter_lines(lines, sys.argv[1])))


if __name__ == '__main__':
    main()
