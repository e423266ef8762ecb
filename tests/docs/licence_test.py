#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Every code file of the source tree says its licence in an SPDX line near its top, and LICENSE is the
Apache License 2.0 that line names: what a user who copies one file needs to know it may.

    licence_test.py --source-dir DIR
"""
import argparse
import pathlib
import sys

SPDX = 'SPDX-License-Identifier: Apache-2.0'
CODE_SUFFIXES = {'.cpp', '.hpp', '.h', '.idl', '.py', '.cmake', '.js', '.css', '.html'}
CODE_NAMES = {'CMakeLists.txt'}
# Inputs of programs, not code: fuzzing seeds and the findings kept as regressions; build trees.
NOT_CODE = {'fuzz/corpus', 'fuzz/regressions'}
SKIPPED_DIRS = {'.git', '__pycache__'}
# Lines from the top of a file within which the SPDX line must be (after a #! line or a doctype).
HEAD_LINES = 3


def is_code(path, relative):
    if any(relative.startswith(prefix + '/') for prefix in NOT_CODE):
        return False
    if path.suffix in CODE_SUFFIXES or path.name in CODE_NAMES or path.name.endswith('.cpp.in'):
        return True
    with open(path, 'rb') as file:
        return file.read(2) == b'#!'


def source_files(root):
    for path in sorted(root.rglob('*')):
        parts = path.relative_to(root).parts
        if any(part in SKIPPED_DIRS or part.startswith('build') for part in parts[:-1]):
            continue
        if path.is_file():
            yield path


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--source-dir', required=True, type=pathlib.Path)
    root = parser.parse_args().source_dir.resolve()
    licence = (root / 'LICENSE').read_text(errors='replace') if (root / 'LICENSE').exists() else ''
    problems = []
    if 'Apache License' not in licence or 'Version 2.0' not in licence:
        problems.append('LICENSE: not the Apache License 2.0 text')
    checked = 0
    for path in source_files(root):
        relative = path.relative_to(root).as_posix()
        if not is_code(path, relative):
            continue
        checked += 1
        head = path.read_text(errors='replace').split('\n')[:HEAD_LINES]
        if not any(SPDX in line for line in head):
            problems.append(f'{relative}:1: no "{SPDX}" line in its first {HEAD_LINES} lines')
    for problem in problems:
        print(problem)
    print(f'{checked} code files checked, {len(problems)} problems')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
