#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""What the documentation says that can be checked mechanically, against the programs themselves:

1. commands: every `cellmap ...` and `cellmapd ...` in a code span or code block of README.md and docs/**/*.md
   names subcommands, flags and choices that the programs' --help lists (`cellmap <sub> --help` for each
   subcommand); a flag named on its own (`--role`) where a command is described (in a section headed by just
   that command, or in a paragraph or list item that starts with it) must be one of that command's; and the
   other way round, docs/cli.md has a section for every subcommand that names each of its options;
2. config keys: every key the tables of docs/config.md list (the first column of a table whose header starts
   with "key") is one the readers read, and every key they read is listed. What the readers read comes from
   the readers (config_keys, tests/docs/config_keys.cpp, records the keys they read or ask about while they
   read the built-in defaults, every shipped file and the files of tests/docs/examples, which use the optional
   sections no shipped file has), not from a second list;
3. shipped files: every YAML file in config/ and config/scenes/ (and tests/docs/examples) is accepted.

Prints one line per finding, "file:line: what is wrong", and exits 1 if there is any.

How docs/config.md is read (so that a rewrite keeps it checkable): a `## ` heading naming `cellmapd.yaml`,
`segment.yaml` or "scene" says whose keys the tables below it list. A table's keys are relative to the
sections named (in backticks) in the paragraph right above it, else in the nearest heading above it; a key
that already starts with that section is taken as written. A key cell may list several keys (`width`,
`height`) and siblings (`robot.gantry.lower`, `.upper`). A key whose value is a map or a list documents the
keys inside it too (`intrinsics`, `{fx, fy, cx, cy}` in its row).

--self-test instead shows that each kind of finding is reported, on made-up docs and help texts.
"""
import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

# --- Markdown: where the docs name commands and keys -------------------------------------------------------

FENCE = re.compile(r'^\s*(```|~~~)')
SPAN = re.compile(r'`([^`]+)`')
HEADING = re.compile(r'^#+\s')
LIST_ITEM = re.compile(r'^\s*(?:[-*+]|\d+\.)\s')
COMMAND_HEADING = re.compile(r'^#+\s+`[^`]+`\s*$')  # a section about one command: ### `cellmap echo`
# A paragraph or list item about one command starts with it: **`cellmap sensors`** lists ..., - `cellmapd ...`:
COMMAND_PARAGRAPH = re.compile(r'^\s*(?:(?:[-*+]|\d+\.)\s+)?[*_]*`(?:[\w.-]*/)?cellmapd?[\s`]')


def markdown_files(source_dir):
    """README.md and every docs/**/*.md, as (path relative to source_dir, lines)."""
    paths = [source_dir / 'README.md'] + sorted((source_dir / 'docs').rglob('*.md'))
    return [(path.relative_to(source_dir), path.read_text(encoding='utf-8').splitlines())
            for path in paths if path.is_file()]


def code_texts(lines):
    """(line number, text, paragraph) of every code span (a span broken over lines is joined) and every line of
    a fenced code block (a line ending in a backslash continues on the next); paragraph: the line its paragraph
    or code block starts on."""
    in_block = False
    paragraph = []  # (line number, text) of the prose lines since the last blank line
    pending = None  # a code block line continued with a backslash

    def spans_of(paragraph_lines):
        text = ''
        starts = []  # (offset, line number)
        for number, line in paragraph_lines:
            starts.append((len(text), number))
            text += line + ' '
        for match in SPAN.finditer(text):
            number = max(n for offset, n in starts if offset <= match.start())
            yield number, match.group(1), starts[0][1]

    block = None  # the line the code block starts on
    for number, line in enumerate(lines, start=1):
        if FENCE.match(line):
            yield from spans_of(paragraph)
            paragraph = []
            in_block = not in_block
            block = number
            continue
        if in_block:
            if pending:
                pending = (pending[0], pending[1] + ' ' + line.strip())
            else:
                pending = (number, line)
            if not line.rstrip().endswith('\\'):
                yield pending[0], pending[1].replace('\\', ' '), block
                pending = None
        elif HEADING.match(line):  # a heading is a paragraph of its own
            yield from spans_of(paragraph)
            yield from spans_of([(number, line)])
            paragraph = []
        elif LIST_ITEM.match(line):  # each item of a list is a paragraph of its own
            yield from spans_of(paragraph)
            paragraph = [(number, line)]
        elif line.strip():
            paragraph.append((number, line))
        else:
            yield from spans_of(paragraph)
            paragraph = []
    yield from spans_of(paragraph)


def heading_lines(lines):
    """The numbers of the lines that are headings (not comments in code blocks)."""
    in_block = False
    numbers = []
    for number, line in enumerate(lines, start=1):
        if FENCE.match(line):
            in_block = not in_block
        elif not in_block and HEADING.match(line):
            numbers.append(number)
    return numbers


# --- Commands: what the programs' --help offers ----------------------------------------------------------

class Command:
    """One program or subcommand as its --help describes it."""

    def __init__(self, help_text):
        self.flags = set()
        self.options = []  # each option's spellings, e.g. ('-o', '--output')
        self.subcommands = set()
        self.choices = []  # each positional's allowed values in order, None where --help lists none
        self.passes_through = False  # a positional takes the remaining words (for another program)
        section = None
        for line in help_text.splitlines():
            heading = re.match(r'^(\w[\w ]*):\s*$', line)
            if heading:
                section = heading.group(1).lower()
                continue
            entry = re.match(r'^ {1,4}(\S.*?)(?:\s{2,}|$)', line)  # deeper: a description's next line
            if not entry:
                continue
            if section == 'options':
                self.flags.update(re.findall(r'(?<![\w-])(--?[A-Za-z][\w-]*)', entry.group(1)))
                spellings = re.sub(r'\{[^}]*\}', '', entry.group(1).split()[0])  # --no-robot{false}
                self.options.append(tuple(spellings.split(',')))
            elif section == 'subcommands':
                self.subcommands.add(entry.group(1).split()[0])
            elif section == 'positionals':
                self.passes_through |= entry.group(1).endswith('...')
                listed = re.search(r'\{([^}]*)\}', entry.group(1))
                self.choices.append({choice.strip() for choice in listed.group(1).split(',')} if listed else None)


class Programs:
    """The --help of cellmap, its subcommands (by path, e.g. ('security', 'init')) and cellmapd, asked once."""

    def __init__(self, run_help):
        self._run_help = run_help  # (program, subcommand path) -> help text
        self._commands = {}

    def command(self, program, path=()):
        key = (program, tuple(path))
        if key not in self._commands:
            self._commands[key] = Command(self._run_help(program, tuple(path)))
        return self._commands[key]


def run_help_of(binaries):
    def run_help(program, path):
        command = [binaries[program], *path, '--help']
        result = subprocess.run(command, capture_output=True, text=True, timeout=30, check=False)
        if result.returncode != 0:
            raise RuntimeError(f'{" ".join(command)} exited {result.returncode}: {result.stderr.strip()}')
        return result.stdout
    return run_help


COMMAND = re.compile(r'(?:^|(?<=\s))(?:[\w.-]*/)?(cellmapd|cellmap)(?=\s|$)')
SHELL_END = re.compile(r'\s(?:\||&&|;|>|2>|#)\s|\s--\s|\s--$')  # where a command's own words end
FLAG = re.compile(r'^(--?[A-Za-z][\w-]*)')
NAME = re.compile(r'^[a-z][a-z0-9-]*([|/][a-z][a-z0-9-]*)*$')  # a subcommand or choice, or several: a|b, a/b
LONE_FLAG = re.compile(r'^(--[a-z][\w-]*)(?:[ =].*)?$')


class Walk:
    """A command line's words followed through the subcommands, with what --help does not know."""

    def __init__(self, where, program, programs):
        self.where = where
        self.program = program
        self.programs = programs
        self.paths = [()]  # several after alternatives (`cellmap echo|inject`)
        self.findings = []
        self.positional = 0
        self.after_flag = False  # the word after a flag is its value, unless it is a subcommand

    def commands(self):
        """The commands the words reached and their parents (whose flags fall through to them)."""
        return [self.programs.command(self.program, path[:depth])
                for path in self.paths for depth in range(len(path) + 1)]

    def passes_through(self):
        """True when a command here hands its remaining words to another program (`cellmap bench`)."""
        return any(command.passes_through for command in self.commands())

    def name(self):
        return ' '.join([self.program, *self.paths[0]]) if len(self.paths) == 1 else \
            f'{self.program} {"|".join(" ".join(path) for path in self.paths)}'

    def flag(self, name):
        self.after_flag = True
        if self.passes_through() and self.positional > 0:
            return
        if not any(name in command.flags for command in self.commands()):
            self.findings.append(f'{self.where}: `{self.name()}` has no flag {name}')

    def word(self, word):
        """A word that is not a flag; False once the rest cannot be followed."""
        subcommands = set().union(*(self.programs.command(self.program, path).subcommands for path in self.paths))
        alternatives = re.split(r'[|/]', word)
        if all(alternative in subcommands for alternative in alternatives):
            self.paths = [path + (alternative,) for path in self.paths for alternative in alternatives
                          if alternative in self.programs.command(self.program, path).subcommands]
            self.after_flag = False
            return True
        if self.after_flag or not NAME.match(word):
            self.after_flag = False  # a value, a placeholder (FILE, N, <cell>) or a path
            return True
        if subcommands:
            self.findings.append(f'{self.where}: `{self.name()}` has no subcommand {word}')
            return False
        choices = self.programs.command(self.program, self.paths[0]).choices
        allowed = choices[self.positional] if len(self.paths) == 1 and self.positional < len(choices) else None
        if allowed:
            wrong = [alternative for alternative in alternatives if alternative not in allowed]
            if wrong:
                self.findings.append(
                    f'{self.where}: `{self.name()}` takes {"|".join(sorted(allowed))}, not {", ".join(wrong)}')
        self.positional += 1
        return True


def walk(where, text, programs):
    """The Walk of the first cellmap or cellmapd command in a code text, or None."""
    match = COMMAND.search(text)
    if not match:
        return None
    result = Walk(where, match.group(1), programs)
    words = text[match.end():]
    end = SHELL_END.search(words)
    for word in (words[:end.start()] if end else words).split():
        flag = FLAG.match(word.strip('[]()|'))
        if flag:
            result.flag(flag.group(1))
        elif not result.word(word.strip('[](){}.,:;`')):
            break
    return result


def lone_flag_findings(where, text, context):
    """A flag named on its own (`--role`) where a command is being described (a section whose heading is just
    that command, ### `cellmap echo`, or a paragraph or list item that starts with it): is it that command's, a
    parent's or a subcommand's? Elsewhere a lone flag may be any program's (a benchmark's, the example
    planner's, one of several commands a sentence names) and is not checked."""
    lone = LONE_FLAG.match(text.strip())
    if not lone or not context or any(walk.passes_through() for walk in context):
        return []
    commands = []
    for walk in context:
        commands += walk.commands()
        pending = list(walk.paths)
        while pending:
            path = pending.pop()
            for sub in walk.programs.command(walk.program, path).subcommands:
                commands.append(walk.programs.command(walk.program, path + (sub,)))
                pending.append(path + (sub,))
    if any(lone.group(1) in command.flags for command in commands):
        return []
    names = ', '.join(dict.fromkeys(f'`{walk.name()}`' for walk in context))
    return [f'{where}: {lone.group(1)} is named for {names}; none of them has it']


def check_commands(docs, programs):
    findings = []
    for path, lines in docs:
        headings = {number: [] for number in heading_lines(lines)}  # -> the Walk of the command it is about
        paragraphs = {}  # paragraph line -> the Walk of the command it starts with
        for number, text, paragraph in code_texts(lines):
            where = f'{path}:{number}'
            heading = max((line for line in headings if line <= number), default=None)
            for part in re.split(r'\s(?:&&|;)\s', text):
                result = walk(where, part, programs)
                if result is not None:
                    findings += result.findings
                    if COMMAND_PARAGRAPH.match(lines[paragraph - 1]):
                        paragraphs.setdefault(paragraph, [result])
                    if heading == number and COMMAND_HEADING.match(lines[number - 1]):
                        headings[heading].append(result)
                else:
                    context = headings.get(heading, []) + paragraphs.get(paragraph, [])
                    findings += lone_flag_findings(where, part, context)
    return findings


def command_paths(programs):
    """(program, subcommand path) of cellmapd, cellmap and every subcommand."""
    paths = [('cellmapd', ())]
    pending = [()]
    while pending:
        path = pending.pop()
        paths.append(('cellmap', path))
        pending += [path + (sub,) for sub in sorted(programs.command('cellmap', path).subcommands)]
    return paths


def check_cli_reference(doc_path, lines, programs):
    """The other way round, for the command-line reference: every subcommand has a section (### `cellmap
    echo`, or one of a parent or a child: `cellmap inject` holds add-box) and every option of a command is
    named in that section."""
    sections = {}  # (program, path) -> (heading line, the section's text)
    numbers = heading_lines(lines) + [len(lines) + 1]
    for start, end in zip(numbers, numbers[1:]):
        if COMMAND_HEADING.match(lines[start - 1]):
            words = SPAN.search(lines[start - 1]).group(1).split()
            key = (words[0], tuple(words[1:]))
            sections[key] = (start, '\n'.join(lines[start - 1:end - 1]))
    findings = []
    for program, path in command_paths(programs):
        related = [key for key in sections if key[0] == program and (
            key[1][:len(path)] == path or (path[:len(key[1])] == key[1] and key[1]))]
        if not related:
            findings.append(f'{doc_path}:1: `{" ".join([program, *path])}` has no section (### `{program} ...`)')
            continue
        own = (program, path) if (program, path) in sections else max(
            (key for key in related if path[:len(key[1])] == key[1]), key=lambda key: len(key[1]), default=None)
        if own is None:
            continue  # documented by its subcommands' sections
        number, text = sections[own]
        for spellings in programs.command(program, path).options:
            if '--help' in spellings:
                continue
            if not any(re.search(rf'(?<![\w-]){re.escape(flag)}(?![\w-])', text) for flag in spellings):
                findings.append(f'{doc_path}:{number}: `{" ".join([program, *path])}` option {"/".join(spellings)} '
                                f'is not described in this section')
    return findings


# --- Config keys: docs/config.md's tables against the readers ---------------------------------------------

READERS = ('daemon', 'segment', 'scene')
# Where one reader reads another's keys: cellmapd's `segment` section is a segment.yaml, its `robot` section
# a scene's robot, and each entry of `sources` is laid over the `source` section.
NESTED = (('daemon', 'segment.', 'segment', ''), ('daemon', 'robot.', 'scene', 'robot.'))


def normalise(key):
    """A key path as docs/config.md writes it: list indices as [i], the entries of `sources` as `source`."""
    key = re.sub(r'\[\d+\]', '[i]', key)
    return re.sub(r'^sources(\[i\])?(?=\.|$)', 'source', key)


def reader_of_heading(title):
    """Whose keys the tables under a `## ` heading list: the one whose file the heading names."""
    lowered = title.lower()
    for reader, marker in (('daemon', 'cellmapd.yaml'), ('segment', 'segment.yaml'), ('scene', 'scene')):
        if marker in lowered:
            return reader
    return None


def key_cells(cell):
    """The keys a table's first cell names: `a`, `b` and `c.d`, `.e` (a sibling of c.d)."""
    keys = []
    for token in SPAN.findall(cell):
        token = token.strip().rstrip(':')
        if token.startswith('.') and keys:
            token = keys[-1].rsplit('.', 1)[0] + token
        if re.match(r'^[A-Za-z_][\w.\[\]]*$', token):
            keys.append(token)
    return keys


def table_sections(paragraph, heading, maps):
    """The sections a key table's keys are relative to: those its paragraph names, else its heading's."""
    for text in (paragraph, heading):
        named = [key for key in map(normalise, key_cells(' '.join(text))) if key in maps]
        if named:
            return list(dict.fromkeys(named))
    return []


def documented_keys(lines, maps):
    """{reader: {key: line number}} from the key tables; `maps(reader)`: the keys that reader reads as maps."""
    keys = {reader: {} for reader in READERS}
    reader = None
    heading_sections = []
    paragraph = []
    in_table = False
    sections = []
    headings = set(heading_lines(lines))
    for number, line in enumerate(lines, start=1):
        heading = re.match(r'^(#+)\s+(.*)$', line) if number in headings else None
        if heading:
            if len(heading.group(1)) <= 2:
                reader = reader_of_heading(heading.group(2))
            heading_sections = [heading.group(2)]
            paragraph = []
            in_table = False
            continue
        if not line.startswith('|'):
            in_table = False
            paragraph = paragraph + [line] if line.strip() else []
            continue
        cells = [cell.strip() for cell in line.strip().strip('|').split('|')]
        if not in_table:
            in_table = True
            is_key_table = reader is not None and cells[0].lower() == 'key'
            sections = table_sections(paragraph, heading_sections, maps(reader)) if is_key_table else None
            continue
        if sections is None or re.match(r'^:?-+', cells[0]):
            continue
        for key in key_cells(cells[0]):
            for section in sections or ['']:
                full = key if not section or key == section or key.startswith(section + '.') \
                    else f'{section}.{key}'
                keys[reader].setdefault(normalise(full), number)
    return keys


def covers(outer, key):
    return key == outer or key.startswith(outer + '.') or key.startswith(outer + '[')


def with_nested(keys_by_reader):
    """Each reader's keys with those it reads through another reader's (NESTED), both ways."""
    merged = {reader: dict(keys) for reader, keys in keys_by_reader.items()}
    for outer, outer_prefix, inner, inner_prefix in NESTED:
        for key, where in keys_by_reader[inner].items():
            if key.startswith(inner_prefix):
                merged[outer].setdefault(outer_prefix + key[len(inner_prefix):], where)
        for key, where in keys_by_reader[outer].items():
            if key.startswith(outer_prefix):
                merged[inner].setdefault(inner_prefix + key[len(outer_prefix):], where)
    return merged


def check_keys(doc_path, lines, read):
    """`read`: {reader: {key: the file it was read from}}."""
    read = with_nested(read)
    maps = {reader: {key.rsplit('.', 1)[0] for key in keys if '.' in key} |
            {key.split('[')[0] for key in keys if '[' in key} for reader, keys in read.items()}
    documented = with_nested(documented_keys(lines, lambda reader: maps.get(reader, set())))
    findings = []
    for reader in READERS:
        for key, number in sorted(documented[reader].items(), key=lambda item: item[1]):
            if not any(covers(key, known) for known in read[reader]):
                findings.append(f'{doc_path}:{number}: {reader} key {key} is not read by the {reader} reader')
        undocumented = []
        for key, source in sorted(read[reader].items()):
            if any(covers(outer, key) for outer in undocumented):
                continue  # inside a key already reported
            if not any(covers(doc, key) or covers(key, doc) for doc in documented[reader]):
                undocumented.append(key)
                number = nearest_line(key, documented[reader])
                findings.append(f'{doc_path}:{number}: {reader} key {key} (read in {source}) is not documented')
    return findings


def nearest_line(key, documented):
    """The line of the documented key that shares the longest leading part of `key` with it (where it
    belongs), else 1."""
    def shared(doc):
        common = 0
        for ours, theirs in zip(re.split(r'[.\[]', key), re.split(r'[.\[]', doc)):
            if ours != theirs:
                break
            common += 1
        return common
    best = max(documented, key=lambda doc: (shared(doc), -documented[doc]), default=None)
    return documented[best] if best and shared(best) else 1


# --- Shipped files and the readers ---------------------------------------------------------------------------

def reader_of_file(path, sections):
    """Which reader a shipped YAML file is for, by its top-level keys; `sections`: {reader: its top-level
    keys}."""
    top = set(re.findall(r'^([A-Za-z_]\w*):', path.read_text(encoding='utf-8'), re.MULTILINE))
    if 'sensors' in top and 'cell' in top:
        return 'scene'
    if top & sections['segment'] and not top & sections['daemon']:
        return 'segment'
    return 'daemon'


def line_of_refused_key(path, message):
    """The line of the key a reader's message names ("file: a.b[2].c: reason"), else 1."""
    named = re.match(r'^[^:]*: ([\w.\[\]]+): ', message)
    if named:
        key = re.split(r'[.\[\]]+', named.group(1).strip('.[]'))[-1]
        for number, line in enumerate(path.read_text(encoding='utf-8').splitlines(), start=1):
            if re.match(rf'^[\s-]*(?:{{\s*)?{re.escape(key)}\s*:', line) or re.search(rf'[{{,]\s*{re.escape(key)}\s*:', line):
                return number
    return 1


def read_config_keys(config_keys, reader, path):
    """(accepted, {reader: keys}, message): the keys config_keys recorded while the reader read `path`."""
    result = subprocess.run([config_keys, reader, str(path)], capture_output=True, text=True, timeout=60,
                            check=False)
    keys = {name: set() for name in READERS}
    for line in result.stdout.splitlines():
        name, key = line.split(' ', 1)
        keys[name].add(normalise(key))
    return result.returncode == 0, keys, result.stderr.strip()


# Files that use what no shipped file does (walkers, camera intrinsics, ...): without one, the keys inside such
# an optional section are not read, and listing them in the docs would be reported as keys nobody reads.
EXAMPLES = 'tests/docs/examples'


def acceptance_command(reader, path, cellmapd):
    """The program that says whether a shipped file is accepted, as a command line (exit 0 = accepted), or
    None: then the readers' own code decides (config_keys, which reads every file for its keys anyway). The
    daemon's files go through `cellmapd --check`, which also checks what only the daemon's start checks."""
    if reader == 'daemon':
        return [cellmapd, '--check', '--config', str(path)]
    return None


def check_shipped_configs(source_dir, config_keys, cellmapd):
    """Findings for refused files, and {reader: {key: a file it was read from}}."""
    findings = []
    read = {reader: {} for reader in READERS}
    with tempfile.NamedTemporaryFile('w', suffix='.yaml') as empty:
        _, keys, _ = read_config_keys(config_keys, 'segment', empty.name)
        sections = {'segment': {key.split('.')[0] for key in keys['segment']}}
        _, keys, _ = read_config_keys(config_keys, 'daemon', empty.name)  # the built-in defaults
        sections['daemon'] = {re.split(r'[.\[]', key)[0] for key in keys['daemon']}
        for key in keys['daemon']:
            read['daemon'].setdefault(key, 'the built-in defaults')
    files = [path for folder in ('config', 'config/scenes', EXAMPLES)
             for path in sorted((source_dir / folder).glob('*.yaml'))]
    for path in files:
        relative = path.relative_to(source_dir)
        reader = reader_of_file(path, sections)
        accepted, keys, message = read_config_keys(config_keys, reader, path)
        command = acceptance_command(reader, path, cellmapd)
        if command:
            result = subprocess.run(command, capture_output=True, text=True, timeout=60, check=False)
            accepted, message = result.returncode == 0, result.stderr or result.stdout
        if not accepted:
            message = ' '.join(message.split())
            number = line_of_refused_key(path, message)
            findings.append(f'{relative}:{number}: refused (read as a {reader} file): {message}')
        for name, names in keys.items():
            for key in names:
                read[name].setdefault(key, str(relative))
    return findings, read


# --- Self-test ------------------------------------------------------------------------------------------------

FAKE_HELP = {
    ('cellmapd', ()): 'Usage: cellmapd [OPTIONS]\n\nOptions:\n  -h,--help  Print\n  --config TEXT  YAML\n',
    ('cellmap', ()): 'Usage: cellmap [OPTIONS] SUBCOMMAND\n\nOptions:\n  -h,--help  Print\n  --version  V\n\n'
                     'Subcommands:\n  bench  Run\n  security  Creds\n',
    ('cellmap', ('bench',)): 'Positionals:\n  kind TEXT:{fusion,segment} REQUIRED  which\n  flags TEXT ...  more\n',
    ('cellmap', ('security',)): 'Subcommands:\n  init  Write\n',
    ('cellmap', ('security', 'init')): 'Options:\n  --cell TEXT  cell\n',
}

FAKE_CONFIG_MD = '''# Configuration files
## cellmapd.yaml
### Top level
| key | default |
|---|---|
| `cell` | `cell-1` |
| `stale` | 0 |
### `source`: the sensor
`source.openni2`:
| key | default |
|---|---|
| `width`, `height` | 640 |
'''

FAKE_CLI_MD = '''# Command lines
## `cellmapd`
Runs the cell.
## `cellmap`
`--version` prints it.
### `cellmap bench`
Runs a benchmark.
'''

FAKE_READ = {'daemon': {'cell': 'x', 'source.openni2.width': 'x', 'source.openni2.height': 'x',
                        'source.openni2.fps': 'x'}, 'segment': {}, 'scene': {}}


def self_test():
    programs = Programs(lambda program, path: FAKE_HELP.get((program, path), ''))
    docs = [(Path('README.md'), ['Run `cellmap bench sim`, `cellmap bench fusion|segment` and',
                                 '`cellmap security init DIR --cell C --days 3`.', '', '```',
                                 'cellmapd --config x.yaml --sweeps 2', 'cellmap nosuch', '```',
                                 '### `cellmap security init`', 'Use `--cell` or `--nothing`;',
                                 '`cellmap security|bench --help`.', '### `cellmap bench`',
                                 'Its own flags: `--benchmark_x`, `cellmap bench fusion --benchmark_y`.'])]
    expected = ['README.md:1: `cellmap bench` takes fusion|segment, not sim',
                'README.md:2: `cellmap security init` has no flag --days',
                'README.md:5: `cellmapd` has no flag --sweeps',
                'README.md:6: `cellmap` has no subcommand nosuch',
                "README.md:9: --nothing is named for `cellmap security init`; none of them has it"]
    expected += ['docs/config.md:7: daemon key stale is not read by the daemon reader',
                 'docs/config.md:12: daemon key source.openni2.fps (read in x) is not documented']
    expected += ['docs/cli.md:2: `cellmapd` option --config is not described in this section',
                 'docs/cli.md:1: `cellmap security` has no section (### `cellmap ...`)',
                 'docs/cli.md:1: `cellmap security init` has no section (### `cellmap ...`)']
    found = check_commands(docs, programs) + check_keys(Path('docs/config.md'), FAKE_CONFIG_MD.splitlines(),
                                                        FAKE_READ)
    found += check_cli_reference(Path('docs/cli.md'), FAKE_CLI_MD.splitlines(), programs)
    if found != expected:
        print('self-test: expected\n  ' + '\n  '.join(expected) + '\nfound\n  ' + '\n  '.join(found))
        return 1
    print(f'self-test: each of the {len(expected)} findings reported')
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--self-test', action='store_true')
    parser.add_argument('--source-dir', type=Path)
    parser.add_argument('--cellmap')
    parser.add_argument('--cellmapd')
    parser.add_argument('--config-keys')
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    if not (args.source_dir and args.cellmap and args.cellmapd and args.config_keys):
        parser.error('--source-dir, --cellmap, --cellmapd and --config-keys are required')
    programs = Programs(run_help_of({'cellmap': args.cellmap, 'cellmapd': args.cellmapd}))
    findings = check_commands(markdown_files(args.source_dir), programs)
    config_findings, read = check_shipped_configs(args.source_dir, args.config_keys, args.cellmapd)
    findings += config_findings
    cli_md = Path('docs/cli.md')
    findings += check_cli_reference(cli_md, (args.source_dir / cli_md).read_text(encoding='utf-8').splitlines(),
                                    programs)
    config_md = Path('docs/config.md')
    findings += check_keys(config_md, (args.source_dir / config_md).read_text(encoding='utf-8').splitlines(),
                           read)
    for finding in findings:
        print(finding)
    print(f'{len(findings)} findings' if findings else 'the docs match the programs')
    return 1 if findings else 0


if __name__ == '__main__':
    sys.exit(main())
