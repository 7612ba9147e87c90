#!/usr/bin/env python3
"""The README's examples run: every code block marked `<!-- docs-check: run -->` (or
`<!-- docs-check: run needs=datasets -->` for blocks that read ../shared/datasets).

  readme_examples.py SOURCE_DIR BUILD_DIR

Blocks run in a scratch copy of the project's layout (examples/ and vocabulary/ linked from the
source, build/release linked to BUILD_DIR, ../shared/datasets to $ORBIS_DATA or the source's
../shared/datasets), so relative paths resolve as in the README and nothing is written into the
source tree: `sh`/`bash` blocks with bash -euo pipefail, `python` blocks with the built module on
PYTHONPATH. Blocks needing the datasets are skipped when they are absent. Exit 0 when every block
ran, 1 naming the block that failed, 77 when every block was skipped.
"""
import os
import pathlib
import re
import subprocess
import sys
import tempfile

MARK = re.compile(r'<!-- docs-check: run( needs=datasets)? -->\s*\n```(\w+)\n(.*?)```', re.S)


def main():
    source, build = pathlib.Path(sys.argv[1]).resolve(), pathlib.Path(sys.argv[2]).resolve()
    data = pathlib.Path(os.environ.get('ORBIS_DATA', source.parent / 'shared' / 'datasets')).resolve()
    readme = (source / 'README.md').read_text(encoding='utf-8')
    blocks = list(MARK.finditer(readme))
    if not blocks:
        print('readme_examples: no block is marked <!-- docs-check: run -->')
        return 1
    ran = 0
    with tempfile.TemporaryDirectory(prefix='orbis-readme-') as scratch:
        repo = pathlib.Path(scratch) / 'orbis'
        (repo / 'build').mkdir(parents=True)
        for name in ('examples', 'vocabulary', 'scripts', 'python'):
            (repo / name).symlink_to(source / name)
        (repo / 'build' / 'release').symlink_to(build)
        if data.is_dir():
            (pathlib.Path(scratch) / 'shared').mkdir()
            (pathlib.Path(scratch) / 'shared' / 'datasets').symlink_to(data)
        env = dict(os.environ, PYTHONPATH=str(build / 'python'))
        for i, m in enumerate(blocks, 1):
            needs_data, language, code = m.group(1), m.group(2), m.group(3)
            line = readme[:m.start()].count('\n') + 1
            if needs_data and not data.is_dir():
                print(f'readme_examples: block {i} (README.md line {line}) skipped: no datasets at {data}')
                continue
            if language == 'python' and not (build / 'python' / 'orbis').is_dir():
                print(f'readme_examples: block {i} (README.md line {line}) skipped: the Python module is not built')
                continue
            if language in ('sh', 'bash'):
                command = ['bash', '-euo', 'pipefail', '-c', code]
            elif language == 'python':
                command = [sys.executable, '-c', code]
            else:
                print(f'readme_examples: block {i} (README.md line {line}): cannot run a {language} block')
                return 1
            print(f'readme_examples: block {i} (README.md line {line}, {language}) ...', flush=True)
            done = subprocess.run(command, cwd=repo, env=env, capture_output=True, text=True, timeout=1200)
            if done.returncode != 0:
                print(done.stdout[-4000:], done.stderr[-4000:], sep='\n')
                print(f'readme_examples: block {i} (README.md line {line}) failed with status {done.returncode}')
                return 1
            ran += 1
    if ran == 0:
        return 77
    print(f'readme_examples: {ran} of {len(blocks)} marked blocks ran')
    return 0


if __name__ == '__main__':
    sys.exit(main())
