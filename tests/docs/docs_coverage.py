#!/usr/bin/env python3
"""The documentation covers the program: every command, action and option `orbis` prints in its
--help, and every settings key the readers accept, appears under docs/.

  docs_coverage.py ORBIS_BINARY SOURCE_DIR

Commands and options come from the program itself (`orbis --help`, `orbis CMD --help`, and
`orbis CMD ACTION --help` for commands with actions), so a new option is checked the day it is
added. An option must appear in a page under docs/ that also names its command (`orbis CMD`).
Settings keys come from `orbis settings-keys --json` (the library's list of what the settings
reader accepts) where the program has that command, and from the sources that read YAML with YamlReader (src/camera/yaml_reader.hpp):
the literal keys of their reads (`yaml.real("Camera.fx")`, `positive(yaml, "Camera.fy")`, ...),
and a prefix passed to a block reader combined with the keys read under it (`LEFT.` + `K`). Keys
read by a settings reader (a source whose name has "settings") must be in the settings reference,
docs/guide/settings.md; keys of other YAML files (EuRoC's sensor.yaml) anywhere under docs/.
Exit 0 when everything is covered; 1 with one line per gap, naming it and where to document it.
"""
import json
import pathlib
import re
import subprocess
import sys

OPTION = re.compile(r'^  (--[A-Za-z0-9][A-Za-z0-9-]*)')
ACTION = re.compile(r'^  ([a-z][a-z0-9-]*)(?: |$)')
COMMAND = re.compile(r'^  ([a-z][a-z0-9-]*) +\S')
KEY_READ = re.compile(r'(?:yaml\.\w+\(\s*|\(\s*yaml\s*,\s*|\berror\(\s*|\bprefix\s*\+\s*)"([^"]+)"')
PREFIX_SUFFIX = re.compile(r'\bprefix\s*\+\s*"([^"]+)"')
KEY_SHAPE = re.compile(r'^[A-Za-z][A-Za-z0-9_]*(\.[A-Za-z0-9_]+)*\.?$')


def run_help(orbis, args):
    """The text a help command prints (standard output and error together)."""
    done = subprocess.run([orbis, *args], capture_output=True, text=True, timeout=60)
    return done.stdout + done.stderr


def section(text, title):
    lines, inside = [], False
    for line in text.splitlines():
        if line.strip() == title:
            inside = True
        elif inside:
            if not line.strip():
                break
            lines.append(line)
    return lines


def mentions(text, token):
    """Whether token appears in text as a whole word (options and keys, not their prefixes)."""
    return re.search(r'(?<![\w.-])' + re.escape(token) + r'(?![\w-])', text) is not None


def command_table(orbis):
    """(command words, options) for every command and action the program lists."""
    table = []
    for line in section(run_help(orbis, ['--help']), 'commands:'):
        m = COMMAND.match(line)
        if not m:
            continue
        name = m.group(1)
        text = run_help(orbis, [name, '--help'])
        actions = [ACTION.match(l).group(1) for l in section(text, 'actions:') if ACTION.match(l)]
        table.append(([name], [OPTION.match(l).group(1) for l in section(text, 'options:') if OPTION.match(l)]))
        for action in actions:
            sub = run_help(orbis, [name, action, '--help'])
            table.append(([name, action],
                          [OPTION.match(l).group(1) for l in section(sub, 'options:') if OPTION.match(l)]))
    return table


def settings_keys(source):
    """(key, file) for every key a YamlReader user reads."""
    keys = []
    for path in sorted((source / 'src').rglob('*.cpp')):
        text = path.read_text(encoding='utf-8')
        if 'yaml_reader.hpp' not in text or path.name == 'yaml_reader.cpp':
            continue
        literals = {m.group(1) for m in KEY_READ.finditer(text) if KEY_SHAPE.match(m.group(1))}
        suffixes = {m.group(1) for m in PREFIX_SUFFIX.finditer(text)}
        prefixes = {k for k in literals if k.endswith('.')}
        for key in sorted(literals - prefixes - suffixes):
            keys.append((key, path))
        for prefix in sorted(prefixes):
            for suffix in sorted(suffixes):
                keys.append((prefix + suffix, path))
    return sorted(set(keys))


def main():
    orbis, source = sys.argv[1], pathlib.Path(sys.argv[2]).resolve()
    pages = {p: p.read_text(encoding='utf-8') for p in sorted((source / 'docs').rglob('*.md'))}
    everything = '\n'.join(pages.values())
    reference = source / 'docs' / 'guide' / 'settings.md'
    gaps = []
    table = command_table(orbis)
    if not table:
        gaps.append(f'{orbis} --help lists no command: cannot check the docs against it')
    for words, options in table:
        name = 'orbis ' + ' '.join(words)
        # An action may be written "orbis vocab train" or, in its command's page, "vocab train".
        spelled = [name, ' '.join(words)] if len(words) > 1 else [name]
        naming = [p for p, text in pages.items() if any(s in text for s in spelled)]
        if not naming:
            gaps.append(f'command `{name}` is not documented under docs/ '
                        f'(add it to docs/guide/commands.md or its topic guide in docs/guide/)')
            continue
        for option in options:
            if option == '--help':
                continue
            if not any(mentions(pages[p], option) for p in naming):
                where = 'nowhere under docs/' if not mentions(everything, option) else \
                    'only in pages that do not name `' + name + '`'
                gaps.append(f'option {option} of `{name}` is documented {where} '
                            f'(document it in the guide that covers `{name}`, e.g. docs/guide/commands.md)')
    keys = settings_keys(source)
    # The library's own list of the keys it reads (`orbis settings-keys`), where the program has it.
    if any(words == ['settings-keys'] for words, _ in table):
        listed = subprocess.run([orbis, 'settings-keys', '--json'], capture_output=True, text=True, timeout=60)
        for entry in json.loads(listed.stdout):
            keys.append((entry['name'], source / 'src' / 'io' / 'settings.cpp'))
        keys = sorted(set(keys))
    if not keys:
        gaps.append('no settings key found in the sources: the key scan no longer matches the readers')
    ref_text = reference.read_text(encoding='utf-8') if reference.exists() else ''
    for key, path in keys:
        rel = path.relative_to(source)
        if 'settings' in path.name:
            if not mentions(ref_text, key):
                gaps.append(f'settings key {key} (read in {rel}) is not in the settings reference docs/guide/settings.md')
        elif not mentions(everything, key):
            gaps.append(f'key {key} (read in {rel}) is not documented under docs/')
    checked = sum(len(o) for _, o in table)
    if gaps:
        print('\n'.join('docs_coverage: ' + g for g in gaps))
        print(f'docs_coverage: {len(gaps)} gap(s) ({len(table)} commands/actions, {checked} options, {len(keys)} keys checked)')
        return 1
    print(f'docs_coverage: {len(table)} commands/actions, {checked} options and {len(keys)} keys, all documented')
    return 0


if __name__ == '__main__':
    sys.exit(main())
