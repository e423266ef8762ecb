"""ROS 2 message types as cellmap writes them in IDL (idl/ros2/<pkg>/msg/<Type>.idl) and as ROS writes them
(.msg files), parsed into one model.

Both parsers give Struct values whose types are spelled as our IDL spells them: a .msg's types are mapped as
rosidl maps them (bool->boolean, byte->octet, char->uint8, float32->float, float64->double,
string<=N->string<N>, T[]->sequence<T>, T[<=N]->sequence<T, N>, T[N]->array, pkg/Type->pkg::msg::dds_::Type_,
constant NAME->NAME_). So an IDL file and its .msg compare member by member.

The IDL subset: modules, @final structs, members (primitive, string<N>, sequence<T[, N]>, scoped names,
T name[N]) and constants in `module Type_Constants`; comments and preprocessor lines are skipped. Stdlib only.
"""

import re
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
