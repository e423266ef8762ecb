#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Every idl/ros2/<pkg>/msg/<Type>.idl against ROS 2's <pkg>/msg/<Type>.msg (<shared data>/ros2): the
struct's name, each field's name, type, order, array size and bounds, and each constant's name, type and
value, by the mapping of idl/ros2/ros2_idl.py. Prints one line per disagreement, naming the file and the
field; exits 1 if there is any. The shared data folder is the environment's CELLMAP_SHARED_DATA if set, else
--shared-data (the build's). Exits 77 (skipped) when it is absent, or 1 under CELLMAP_REQUIRE_DATA=1, saying so
in the words of tests/support/shared_data.hpp (scripts/test counts the skips by them).

--self-test instead shows that the check catches drift: a made-up .msg, its IDL, and that IDL drifted one way
at a time (order, type, size, bound, constant, ...), each of which must be reported.
"""
import argparse
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'idl' / 'ros2'))
from ros2_idl import parse_idl, parse_msg  # noqa: E402

SKIPPED = 77  # ctest's SKIP_RETURN_CODE for this test
SHARED_DATA_MISSING = 'shared test data missing (CELLMAP_SHARED_DATA)'  # as kSharedDataMissing


def _compare(kind, ours, theirs, describe):
    """Disagreements between two lists of named things (IDL first, .msg second), by name."""
    ours_by_name = {item.name: item for item in ours}
    theirs_by_name = {item.name: item for item in theirs}
    lines = [f"{kind} '{item.name}' ({describe(item)}) of the .msg is missing"
             for item in theirs if item.name not in ours_by_name]
    lines += [f"{kind} '{item.name}' is not in the .msg" for item in ours if item.name not in theirs_by_name]
    ours_common = [item.name for item in ours if item.name in theirs_by_name]
    theirs_common = [item.name for item in theirs if item.name in ours_by_name]
    if kind == 'field' and ours_common != theirs_common:
        positions = {item.name: index + 1 for index, item in enumerate(theirs)}
        lines += [f"field '{name}' is field {index + 1} here, {positions[name]} in the .msg"
                  for index, name in enumerate(item.name for item in ours)
                  if name in theirs_by_name and ours_common.index(name) != theirs_common.index(name)]
    for item in ours:
        other = theirs_by_name.get(item.name)
        if other is not None and describe(item) != describe(other):
            lines.append(f"{kind} '{item.name}': {describe(item)} here, {describe(other)} in the .msg")
    return lines


def disagreements(idl, msg):
    """What differs between the Struct of an IDL file and that of its .msg, one line each."""
    if idl.scoped_name != msg.scoped_name:
        return [f'defines {idl.scoped_name}, expected {msg.scoped_name}']
    lines = [] if idl.final else [f'{idl.scoped_name} is not @final']
    lines += _compare('field', idl.members, msg.members, lambda member: str(member.type))
    lines += _compare('constant', idl.constants, msg.constants,
                      lambda constant: f'{constant.type} = {constant.value!r}')
    return lines


def text_disagreements(idl_text, msg_text, ros_type):
    """Disagreements of an IDL text with the .msg text of `ros_type`, parse errors included."""
    try:
        structs = parse_idl(idl_text)
        msg = parse_msg(msg_text, ros_type)
    except ValueError as error:
        return [str(error)]
    if len(structs) != 1:
        return [f'defines {len(structs)} structs, expected one: {msg.scoped_name}']
    return disagreements(structs[0], msg)


def file_disagreements(idl_path, idl_root, msg_root):
    """Disagreements of one file of idl/ros2 with its .msg."""
    parts = idl_path.relative_to(idl_root).parts
    if len(parts) != 3 or parts[1] != 'msg':
        return ['not in <package>/msg/']
    msg_path = msg_root / parts[0] / 'msg' / (idl_path.stem + '.msg')
    if not msg_path.exists():
        return [f'{msg_path} does not exist']
    return text_disagreements(idl_path.read_text(encoding='utf-8'), msg_path.read_text(encoding='utf-8'),
                              f'{parts[0]}/msg/{idl_path.stem}')


def check(idl_root, msg_root):
    if not msg_root.exists():
        if os.environ.get('CELLMAP_REQUIRE_DATA') == '1':
            print(f'{msg_root} is absent and CELLMAP_REQUIRE_DATA=1 requires the shared data')
            return 1
        print(f'{SHARED_DATA_MISSING}: "{msg_root}" is absent')
        return SKIPPED
    idl_files = sorted(idl_root.rglob('*.idl'))
    problems = [f'{idl_root}: no IDL files'] if not idl_files else []
    for path in idl_files:
        label = path.relative_to(idl_root.parents[1])
        problems += [f'{label}: {line}' for line in file_disagreements(path, idl_root, msg_root)]
    for line in problems:
        print(line)
    print(f'{len(idl_files)} IDL files, {len(problems)} disagreements with ROS 2\'s .msg files')
    return 1 if problems else 0


# A made-up message with each construct the check reads, and its IDL by our mapping.
SAMPLE_MSG = '''# Comments, constants with and without spaces, defaults, bounds and nested types.
uint8 RED=1  # a trailing comment
float64 SCALE = 0.5
string NAME="cell"
std_msgs/Header header
Point position        # a type of the same package
float64[3] covariance
int32[<=4] ids
string<=8 label "none"
float64 weight 1.0
char letter
byte flags
bool ok
'''
SAMPLE_IDL = '''// The IDL of SAMPLE_MSG.
#include "std_msgs/msg/Header.idl"
module sample_msgs {
  module msg {
    module dds_ {
      module Sample_Constants {
        const uint8 RED_ = 1;
        const double SCALE_ = 0.5;
        const string NAME_ = "cell";
      };
      @final
      struct Sample_ {
        std_msgs::msg::dds_::Header_ header;
        sample_msgs::msg::dds_::Point_ position;
        double covariance[3];
        sequence<int32, 4> ids;
        string<8> label;
        double weight;
        uint8 letter;
        octet flags;
        boolean ok;
      };
    };
  };
};
'''
# (drift, text of SAMPLE_IDL, its replacement, what the report must say)
DRIFTS = [
    ('swapped fields', 'double weight;\n        uint8 letter;', 'uint8 letter;\n        double weight;',
     "field 'weight' is field 7 here, 6 in the .msg"),
    ('wrong type', 'sequence<int32, 4> ids', 'sequence<int64, 4> ids',
     "field 'ids': sequence<int64, 4> here, sequence<int32, 4> in the .msg"),
    ('byte as uint8', 'octet flags', 'uint8 flags', "field 'flags': uint8 here, octet in the .msg"),
    ('array size', 'covariance[3]', 'covariance[4]', "field 'covariance': double[4] here, double[3] in"),
    ('sequence bound', 'sequence<int32, 4>', 'sequence<int32>', "field 'ids': sequence<int32> here"),
    ('array for sequence', 'sequence<int32, 4> ids', 'int32 ids[4]', "field 'ids': int32[4] here"),
    ('string bound', 'string<8> label', 'string label', "field 'label': string here, string<8> in"),
    ('nested type', 'sample_msgs::msg::dds_::Point_', 'geometry_msgs::msg::dds_::Point_',
     "field 'position': geometry_msgs::msg::dds_::Point_ here, sample_msgs::msg::dds_::Point_ in"),
    ('missing field', '        boolean ok;\n', '', "field 'ok' (boolean) of the .msg is missing"),
    ('renamed field', 'boolean ok;', 'boolean okay;', "field 'okay' is not in the .msg"),
    ('missing constant', '        const double SCALE_ = 0.5;\n', '',
     "constant 'SCALE_' (double = 0.5) of the .msg is missing"),
    ('constant value', 'RED_ = 1', 'RED_ = 2', "constant 'RED_': uint8 = 2 here, uint8 = 1 in the .msg"),
    ('constant type', 'const uint8 RED_', 'const int8 RED_', "constant 'RED_': int8 = 1 here"),
    ('constant without underscore', 'NAME_ =', 'NAME =', "constant 'NAME' is not in the .msg"),
    ('not @final', '@final\n', '', 'sample_msgs::msg::dds_::Sample_ is not @final'),
    ('module', 'module dds_', 'module dds',
     'defines sample_msgs::msg::dds::Sample_, expected sample_msgs::msg::dds_::Sample_'),
    ('two structs', '@final\n', '@final struct Extra_ { boolean on; };\n', 'defines 2 structs, expected one'),
]


def self_test():
    failures = []
    reported = text_disagreements(SAMPLE_IDL, SAMPLE_MSG, 'sample_msgs/msg/Sample')
    if reported:
        failures.append(f'the matching IDL is reported: {reported}')
    for drift, text, replacement, expected in DRIFTS:
        assert text in SAMPLE_IDL, drift
        drifted = SAMPLE_IDL.replace(text, replacement, 1)
        reported = text_disagreements(drifted, SAMPLE_MSG, 'sample_msgs/msg/Sample')
        if not any(expected in line for line in reported):
            failures.append(f'{drift}: expected a line with "{expected}", got {reported}')
    for line in failures:
        print(line)
    print(f'{len(DRIFTS)} drifts, {len(failures)} not reported as expected')
    return 1 if failures else 0


def main():
    arguments = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    arguments.add_argument('--idl-root', type=Path, help='idl/ros2')
    arguments.add_argument('--shared-data', type=Path,
                           help='the shared data folder, unless the environment\'s CELLMAP_SHARED_DATA names one')
    arguments.add_argument('--self-test', action='store_true', help='check that drift is caught')
    options = arguments.parse_args()
    if options.self_test:
        return self_test()
    shared_data = os.environ.get('CELLMAP_SHARED_DATA') or options.shared_data
    if not options.idl_root or not shared_data:
        arguments.error('--idl-root and --shared-data (or CELLMAP_SHARED_DATA) are needed')
    return check(options.idl_root, Path(shared_data) / 'ros2')


if __name__ == '__main__':
    sys.exit(main())
