# SPDX-License-Identifier: Apache-2.0
"""ROS 2 message types as cellmap writes them in IDL (idl/ros2/<pkg>/msg/<Type>.idl) and as ROS writes them
(.msg files), parsed into one model; and their REP 2011 type hashes (RIHS01).

Both parsers give Struct values whose types are spelled as our IDL spells them: a .msg's types are mapped as
rosidl maps them (bool->boolean, byte->octet, char->uint8, float32->float, float64->double,
string<=N->string<N>, T[]->sequence<T>, T[<=N]->sequence<T, N>, T[N]->array, pkg/Type->pkg::msg::dds_::Type_,
constant NAME->NAME_). So an IDL file and its .msg compare member by member, and the hash is computed from our
IDL alone.

The IDL subset: modules, @final structs, members (primitive, string<N>, sequence<T[, N]>, scoped names,
T name[N]) and constants in `module Type_Constants`; comments and preprocessor lines are skipped. Stdlib only.

Build time: `python3 ros2_idl.py --header OUT.h IDL...` writes the C++ table of every struct's type hash.
"""

import argparse
import hashlib
import json
import re
import sys
from dataclasses import dataclass
from typing import Tuple

# .msg primitive -> IDL primitive (rosidl_adapter's mapping; char is uint8 on the wire and in the hash).
MSG_TO_IDL = {
    'bool': 'boolean', 'byte': 'octet', 'char': 'uint8',
    'int8': 'int8', 'uint8': 'uint8', 'int16': 'int16', 'uint16': 'uint16',
    'int32': 'int32', 'uint32': 'uint32', 'int64': 'int64', 'uint64': 'uint64',
    'float32': 'float', 'float64': 'double', 'string': 'string', 'wstring': 'wstring',
}
IDL_PRIMITIVES = set(MSG_TO_IDL.values())
INTEGERS = {'octet', 'uint8', 'int8', 'int16', 'uint16', 'int32', 'uint32', 'int64', 'uint64'}
STRINGS = {'string', 'wstring'}


@dataclass(frozen=True)
class Type:
    """One member's type. `base` is an IDL primitive or a scoped name (pkg::msg::dds_::Type_); `kind` is
    'single', 'array' (size = its length) or 'sequence' (size = its bound, 0 when unbounded)."""
    base: str
    string_bound: int = 0
    kind: str = 'single'
    size: int = 0

    def __str__(self):
        element = f'{self.base}<{self.string_bound}>' if self.string_bound else self.base
        if self.kind == 'array':
            return f'{element}[{self.size}]'
        if self.kind == 'sequence':
            return f'sequence<{element}, {self.size}>' if self.size else f'sequence<{element}>'
        return element


@dataclass(frozen=True)
class Member:
    name: str
    type: Type


@dataclass(frozen=True)
class Constant:
    name: str  # as IDL spells it: the .msg's name with a trailing underscore
    type: Type
    value: object  # int, float, bool or str, so that 1, 0x1 and 1.0 compare by value


@dataclass(frozen=True)
class Struct:
    scoped_name: str  # pkg::msg::dds_::Type_
    members: Tuple[Member, ...]
    constants: Tuple[Constant, ...]
    final: bool

    @property
    def ros_type(self):
        return ros_type_of(self.scoped_name)


def scoped_name_of(ros_type):
    """'pkg/msg/Type' -> 'pkg::msg::dds_::Type_'."""
    package, _, name = ros_type.split('/')
    return f'{package}::msg::dds_::{name}_'


def ros_type_of(scoped_name):
    """'pkg::msg::dds_::Type_' -> 'pkg/msg/Type'; ValueError for a name ROS does not map to."""
    parts = scoped_name.split('::')
    if len(parts) != 4 or parts[1:3] != ['msg', 'dds_'] or not parts[3].endswith('_'):
        raise ValueError(f'{scoped_name} is not a ROS 2 message type (pkg::msg::dds_::Type_)')
    return f'{parts[0]}/msg/{parts[3][:-1]}'


def constant_value(type_, text):
    """The value of a constant's literal, normalized by its type (ROS and IDL spell them differently)."""
    if type_.base in INTEGERS:
        try:
            return int(text)
        except ValueError:
            return int(text, 0)
    if type_.base in ('float', 'double'):
        return float(text)
    if type_.base == 'boolean':
        if text.lower() not in ('true', 'false', '1', '0'):
            raise ValueError(f'{text} is not a boolean')
        return text.lower() in ('true', '1')
    if type_.base in STRINGS and len(text) >= 2 and text[0] == text[-1] and text[0] in '"\'':
        return text[1:-1]
    return text


# --- .msg ---------------------------------------------------------------------------------------------------

MSG_TYPE = re.compile(r'(?P<base>[A-Za-z][\w/]*)(?:<=(?P<string_bound>\d+))?'
                      r'(?:\[(?P<bounded><=)?(?P<size>\d*)\])?')


def parse_msg_type(text, package):
    match = MSG_TYPE.fullmatch(text)
    if not match or (match['bounded'] and not match['size']):
        raise ValueError(f'bad type {text!r}')
    base = match['base']
    if base in MSG_TO_IDL:
        base = MSG_TO_IDL[base]
    else:
        # Nested: 'pkg/Type', or 'Type' of the message's own package.
        nested_package, _, name = base.rpartition('/')
        base = scoped_name_of(f'{nested_package or package}/msg/{name}')
    if match['string_bound'] and base not in STRINGS:
        raise ValueError(f'bad type {text!r}: only strings have a bound')
    string_bound = int(match['string_bound'] or 0)
    if match['size'] is None:
        return Type(base, string_bound)
    if match['bounded'] or not match['size']:
        return Type(base, string_bound, 'sequence', int(match['size'] or 0))
    return Type(base, string_bound, 'array', int(match['size']))


def parse_msg(text, ros_type):
    """Parses a .msg file of message `ros_type` ('pkg/msg/Type'). As rosidl does: '#' starts a comment
    anywhere on a line; a line is `TYPE NAME=VALUE` (constant) or `TYPE name [default]` (field)."""
    package = ros_type.split('/')[0]
    members, constants = [], []
    for number, line in enumerate(text.replace('\t', ' ').splitlines(), 1):
        line = line.split('#', 1)[0].strip()
        if not line:
            continue
        type_text, _, rest = line.partition(' ')
        rest = rest.strip()
        try:
            type_ = parse_msg_type(type_text, package)
            if '=' in rest:
                name, _, value = rest.partition('=')
                constants.append(Constant(name.strip() + '_', type_, constant_value(type_, value.strip())))
            elif rest:
                # A default value (`float64 w 1`) is part of neither the wire type nor the type hash.
                members.append(Member(rest.split(' ', 1)[0], type_))
            else:
                raise ValueError('a field needs a name')
        except ValueError as error:
            raise ValueError(f'line {number}: {error}') from None
    return Struct(scoped_name_of(ros_type), tuple(members), tuple(constants), final=True)


# --- IDL ----------------------------------------------------------------------------------------------------

IDL_TOKEN = re.compile(r'"(?:\\.|[^"\\])*"|0[xX][0-9a-fA-F]+|\d+\.?\d*(?:[eE][-+]?\d+)?|[A-Za-z_]\w*|::|\S')
IDL_COMMENT = re.compile(r'//[^\n]*|/\*.*?\*/|^[ \t]*#[^\n]*', re.DOTALL | re.MULTILINE)


class _IdlParser:
    def __init__(self, text):
        self.tokens = IDL_TOKEN.findall(IDL_COMMENT.sub(' ', text))
        self.at = 0
        self.structs = []
        self.constants = {}  # struct's scoped name -> constants of its Type_Constants module

    def peek(self):
        return self.tokens[self.at] if self.at < len(self.tokens) else ''

    def take(self, expected=None):
        token = self.peek()
        if not token or (expected is not None and token != expected):
            context = ' '.join(self.tokens[max(0, self.at - 6):self.at + 1])
            raise ValueError(f'expected {expected or "more"}, got {token or "the end"!r} after: {context}')
        self.at += 1
        return token

    def number(self):
        return constant_value(Type('uint64'), self.take())

    def scoped_name(self):
        name = self.take()
        while self.peek() == '::':
            name += self.take() + self.take()
        return name

    def type(self):
        if self.peek() == 'sequence':
            self.take()
            self.take('<')
            element = self.type()
            bound = 0
            if self.peek() == ',':
                self.take()
                bound = self.number()
            self.take('>')
            return Type(element.base, element.string_bound, 'sequence', bound)
        base = self.scoped_name()
        if base in STRINGS and self.peek() == '<':
            self.take()
            bound = self.number()
            self.take('>')
            return Type(base, bound)
        if base not in IDL_PRIMITIVES and '::' not in base:
            raise ValueError(f'type {base} is outside the subset of idl/ros2')
        return Type(base)

    def annotations(self):
        names = []
        while self.peek() == '@':
            self.take()
            names.append(self.take())
            if self.peek() == '(':
                depth = 0
                while True:
                    token = self.take()
                    depth += {'(': 1, ')': -1}.get(token, 0)
                    if depth == 0:
                        break
        return names

    def definitions(self, scope):
        while self.peek() and self.peek() != '}':
            annotations = self.annotations()
            keyword = self.take()
            if keyword == 'module':
                name = self.take()
                self.take('{')
                self.definitions(scope + [name])
                self.take('}')
            elif keyword == 'struct':
                self.struct(scope, 'final' in annotations)
            elif keyword == 'const':
                self.constant(scope)
            else:
                raise ValueError(f'{keyword} is outside the subset of idl/ros2')
            self.take(';')

    def struct(self, scope, final):
        name = '::'.join(scope + [self.take()])
        self.take('{')
        members = []
        while self.peek() != '}':
            self.annotations()
            type_ = self.type()
            member = self.take()
            if self.peek() == '[':
                self.take()
                type_ = Type(type_.base, type_.string_bound, 'array', self.number())
                self.take(']')
            self.take(';')
            members.append(Member(member, type_))
        self.take('}')
        self.structs.append((name, tuple(members), final))

    def constant(self, scope):
        if not scope or not scope[-1].endswith('_Constants'):
            raise ValueError('constants belong in a module Type_Constants')
        type_ = self.type()
        name = self.take()
        self.take('=')
        value = ''
        while self.peek() != ';':
            value += self.take()
        owner = '::'.join(scope[:-1] + [scope[-1][:-len('Constants')]])
        self.constants.setdefault(owner, []).append(Constant(name, type_, constant_value(type_, value)))


def parse_idl(text):
    """The structs of an IDL text, each with the constants of its Type_Constants module."""
    parser = _IdlParser(text)
    parser.definitions([])
    if parser.peek():
        raise ValueError(f'unexpected {parser.peek()!r} at the top level')
    structs = [Struct(name, members, tuple(parser.constants.pop(name, ())), final)
               for name, members, final in parser.structs]
    if parser.constants:
        raise ValueError(f'constants without a struct: {", ".join(sorted(parser.constants))}')
    return structs


# --- REP 2011 type hashes -----------------------------------------------------------------------------------

# type_description_interfaces/msg/FieldType: the id of each element type; arrays, bounded and unbounded
# sequences of it add 48, 96 and 144.
FIELD_TYPE_IDS = {
    'nested': 1, 'int8': 2, 'uint8': 3, 'int16': 4, 'uint16': 5, 'int32': 6, 'uint32': 7, 'int64': 8,
    'uint64': 9, 'float': 10, 'double': 11, 'boolean': 15, 'octet': 16, 'string': 17, 'wstring': 18,
    'bounded string': 21, 'bounded wstring': 22,
}


def _field_type(type_):
    if type_.base in IDL_PRIMITIVES:
        element = f'bounded {type_.base}' if type_.string_bound else type_.base
        nested = ''
    else:
        element, nested = 'nested', ros_type_of(type_.base)
    offset = {'single': 0, 'array': 48}.get(type_.kind, 96 if type_.size else 144)
    # Key order matters: the hash is over this JSON text as written.
    return {'type_id': FIELD_TYPE_IDS[element] + offset, 'capacity': type_.size,
            'string_capacity': type_.string_bound, 'nested_type_name': nested}


def _individual_description(struct):
    return {'type_name': struct.ros_type,
            'fields': [{'name': member.name, 'type': _field_type(member.type)} for member in struct.members]}


def type_description(ros_type, structs):
    """REP 2011's TypeDescription of `ros_type` (as hashed: no default values): the type and every type it
    references, directly or not, sorted by name. `structs` maps ROS type names to Struct."""
    referenced, pending = set(), [ros_type]
    while pending:
        name = pending.pop()
        if name not in structs:
            raise ValueError(f'{name} (referenced by {ros_type}) is not defined')
        for member in structs[name].members:
            if member.type.base not in IDL_PRIMITIVES:
                nested = ros_type_of(member.type.base)
                if nested not in referenced:
                    referenced.add(nested)
                    pending.append(nested)
    return {'type_description': _individual_description(structs[ros_type]),
            'referenced_type_descriptions': [_individual_description(structs[name])
                                             for name in sorted(referenced)]}


def type_hash(ros_type, structs):
    """'RIHS01_' + sha256 of the type description as JSON with ', ' and ': ' separators and ASCII escapes,
    the form rosidl hashes (REP 2011)."""
    text = json.dumps(type_description(ros_type, structs), separators=(', ', ': '), ensure_ascii=True)
    return 'RIHS01_' + hashlib.sha256(text.encode('utf-8')).hexdigest()


def type_hashes(structs):
    """ROS type name -> RIHS01 hash for every struct of `structs` (a list)."""
    by_name = {struct.ros_type: struct for struct in structs}
    return {name: type_hash(name, by_name) for name in sorted(by_name)}


def header_text(hashes):
    rows = ''.join(f'    {{"{name}", "{value}"}},\n' for name, value in hashes.items())
    return ('// Generated by idl/ros2/ros2_idl.py from idl/ros2/*/msg/*.idl at build time: do not edit.\n'
            '// The REP 2011 type hash (RIHS01) of every ROS 2 message type of idl/ros2, sorted by name.\n'
            '#pragma once\n\n'
            'namespace cellmap::ros2::generated {\n\n'
            'struct TypeHashRow {\n  const char* ros_type;\n  const char* hash;\n};\n\n'
            f'inline constexpr TypeHashRow kTypeHashes[] = {{\n{rows}}};\n\n'
            '}  // namespace cellmap::ros2::generated\n')


def main(argv):
    arguments = argparse.ArgumentParser(description='Writes the type hashes of ROS 2 types defined in IDL.')
    arguments.add_argument('--header', required=True, help='C++ header to write')
    arguments.add_argument('idl', nargs='+', help='IDL files (idl/ros2/<pkg>/msg/<Type>.idl)')
    options = arguments.parse_args(argv)
    structs = []
    for path in options.idl:
        with open(path, encoding='utf-8') as file:
            try:
                structs += parse_idl(file.read())
            except ValueError as error:
                sys.exit(f'{path}: {error}')
    try:
        text = header_text(type_hashes(structs))
    except ValueError as error:
        sys.exit(str(error))
    with open(options.header, 'w', encoding='utf-8') as file:
        file.write(text)


if __name__ == '__main__':
    main(sys.argv[1:])
