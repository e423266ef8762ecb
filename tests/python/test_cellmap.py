# SPDX-License-Identifier: Apache-2.0
"""The Python module `cellmap` against the real parts: cellmapd and `cellmap echo`/`inject`/`distance`/
`security` as processes on loopback DDS (domains 213, and 215 with DDS Security), the IRB 2400 URDF of the
shared data. Run by ctest (python_module)
with PYTHONPATH at the built module and CELLMAPD, CELLMAP_TOOL and CELLMAP_SHARED_DATA set.
"""
import json
import math
import os
import subprocess
import tempfile

import numpy as np
import pytest

import cellmap

DOMAIN = 213
CELL = 'python-cell'
PATIENCE = 90  # seconds; the machine is shared
LOOPBACK = ('<CycloneDDS><Domain Id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/>'
            '</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>'
            '<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>30</MaxAutoParticipantIndex>'
            '<Peers><Peer address="127.0.0.1"/></Peers><LeaseDuration>1 s</LeaseDuration></Discovery>'
            '</Domain></CycloneDDS>')
NEW_BOX = ['add-box', '--center', '2.12,0.45,0.9', '--half-extents', '0.1,0.1,0.15']


def box(center, half_extents, rotation=(1.0, 0.0, 0.0, 0.0)):
    return np.array([*center, *half_extents, *rotation], dtype=float)


def about_z(angle):
    return (math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2))


# Pairs with known answers and awkward ones: separated, touching, overlapping, rotated, identical.
PAIRS = [
    (box((0, 0, 0), (0.5, 0.5, 0.5)), box((2, 0, 0), (0.5, 0.5, 0.5))),
    (box((0, 0, 0), (0.5, 0.5, 0.5)), box((1, 0, 0), (0.5, 0.5, 0.5))),
    (box((0, 0, 0), (0.5, 0.5, 0.5)), box((0.7, 0.2, 0.1), (0.5, 0.3, 0.5), about_z(0.3))),
    (box((0, 0, 0), (0.2, 0.4, 0.1), about_z(1.0)), box((1.1, -0.7, 0.3), (0.3, 0.1, 0.6), about_z(-0.4))),
    (box((1, 2, 3), (0.1, 0.1, 0.1)), box((1, 2, 3), (0.1, 0.1, 0.1))),
]


def tool():
    return os.environ['CELLMAP_TOOL']


def run_tool(*args):
    return subprocess.run([tool(), *args], capture_output=True, text=True, timeout=PATIENCE, check=True).stdout


def box_text(b):
    return ','.join(repr(float(v)) for v in b)


def test_distance_equals_the_cli_bit_for_bit():
    for a, b in PAIRS:
        ours = cellmap.distance(a, b)
        cli = json.loads(run_tool('distance', box_text(a), box_text(b)))
        assert ours['distance'] == cli['distance']
        for key in ('point_a', 'point_b', 'normal'):
            assert ours[key].tolist() == cli[key]
        assert np.allclose(ours['point_b'], ours['point_a'] + ours['distance'] * ours['normal'])
    assert cellmap.distance(*PAIRS[0])['distance'] == 1.0


def test_batch_distance_is_every_pair_of_the_single_distance():
    rng = np.random.default_rng(7)
    robot = np.stack([np.stack([box(rng.uniform(-1, 1, 3), rng.uniform(0.05, 0.3, 3), about_z(rng.uniform(0, 3)))
                                for _ in range(4)]) for _ in range(3)])  # 3 checkpoints of 4 boxes
    environment = np.stack([box(rng.uniform(-1, 1, 3), rng.uniform(0.05, 0.3, 3)) for _ in range(5)])
    batch = cellmap.batch_distance(robot, environment)
    assert batch['distance'].shape == (3, 4, 5)
    assert batch['normal'].shape == (3, 4, 5, 3)
    for k in range(3):
        for r in range(4):
            for e in range(5):
                single = cellmap.distance(robot[k, r], environment[e])
                assert batch['distance'][k, r, e] == single['distance']
                assert batch['point_a'][k, r, e].tolist() == single['point_a'].tolist()
    assert cellmap.batch_distance(robot[0], environment)['distance'].shape == (4, 5)
    # A loop reuses its result: the same arrays, filled again with the same values.
    again = cellmap.batch_distance(robot, environment, out=batch)
    assert again is batch and np.array_equal(again['distance'], cellmap.batch_distance(robot, environment)['distance'])
    with pytest.raises(ValueError, match="out\\['distance'\\]: not a writable C-ordered array of the result's shape"):
        cellmap.batch_distance(robot[0], environment, out=batch)


def test_spheres_cover_the_box_and_bound_its_distance_from_below():
    a, b = PAIRS[0]
    cover_a, cover_b = cellmap.sphere_cover(a, 6), cellmap.sphere_cover(b, 6)
    assert cover_a.shape == (6, 4)
    corners = [a[:3] + np.array(s) * a[3:6] for s in np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).T.reshape(-1, 3)]
    for corner in corners:  # every corner of the box lies in some sphere
        assert min(np.linalg.norm(corner - c[:3]) - c[3] for c in cover_a) <= 1e-12
    assert cellmap.sphere_set_distance(cover_a, cover_b) <= cellmap.distance(a, b)['distance']
    assert cellmap.sphere_box_distance(np.array([3.0, 0, 0, 0.25]), b) == pytest.approx(0.25)


def test_bad_arguments_raise_value_or_type_errors_that_say_what():
    good = PAIRS[0][0]
    with pytest.raises(ValueError, match=r'boxes are arrays of 10 values .* not of shape \(9\)'):
        cellmap.distance(np.zeros(9), good)
    with pytest.raises(ValueError, match=r'a\[0\]: not a finite number'):
        cellmap.distance(box((math.nan, 0, 0), (1, 1, 1)), good)
    with pytest.raises(ValueError, match='a half extent is negative'):
        cellmap.distance(box((0, 0, 0), (-1, 1, 1)), good)
    with pytest.raises(ValueError, match='not a unit quaternion'):
        cellmap.distance(box((0, 0, 0), (1, 1, 1), (2, 0, 0, 0)), good)
    with pytest.raises(TypeError):
        cellmap.distance('a box', good)
    with pytest.raises(ValueError, match=r'robot: boxes of shape \(R, 10\) or \(K, R, 10\)'):
        cellmap.batch_distance(good, np.stack([good]))
    with pytest.raises(ValueError, match='domain: 300 is not in 0-232'):
        cellmap.EnvironmentSubscriber(domain=300)
    with pytest.raises(ValueError, match='role'):
        cellmap.EnvironmentSubscriber(domain=DOMAIN, security='/nonexistent', role='admiral')
    with pytest.raises(cellmap.Error, match='/nonexistent'):
        cellmap.EnvironmentSubscriber(domain=DOMAIN, security='/nonexistent')
    with pytest.raises(ValueError, match='n: at least one sphere'):
        cellmap.sphere_cover(good, 0)


def test_boxes_json_round_trip(tmp_path):
    environment = cellmap.Environment('cell', 4, 0, np.stack([a for a, _ in PAIRS]), ids=[5, 6, 7, 8, 9])
    cellmap.write_boxes(str(tmp_path / 'boxes.json'), environment)
    back = cellmap.read_boxes(str(tmp_path / 'boxes.json'))
    assert back.version == 4 and back.ids.tolist() == [5, 6, 7, 8, 9]
    assert np.array_equal(back.boxes, environment.boxes)
    with pytest.raises(cellmap.Error, match='repeated|twice|share'):
        cellmap.Environment('cell', 1, 0, np.stack([PAIRS[0][0]] * 2), ids=[1, 1])


def shared_urdf():
    data = os.environ.get('CELLMAP_SHARED_DATA', '')
    path = os.path.join(data, 'robots', 'abb_irb2400_support', 'urdf', 'irb2400.urdf')
    if not os.path.exists(path):
        if os.environ.get('CELLMAP_REQUIRE_DATA') == '1':
            pytest.fail(f'{path} not found (CELLMAP_SHARED_DATA)')
        pytest.skip(f'{path} not found (CELLMAP_SHARED_DATA)')
    return path


def test_path_checker_finds_the_box_in_the_robots_way_and_passes_a_clear_path():
    checker = cellmap.PathChecker(shared_urdf(), 'tool0')
    assert checker.dof == 6
    home = np.zeros(6)
    placed = checker.place(home)
    assert placed.shape == (checker.boxes, 10)
    tool_box = placed[-1]
    in_the_way = cellmap.Environment('cell', 1, 0, np.stack([box(tool_box[:3], (0.05, 0.05, 0.05))]), ids=[42])
    far = cellmap.Environment('cell', 1, 0, np.stack([box((10, 10, 10), (0.05, 0.05, 0.05))]), ids=[42])
    path = np.stack([home, home + 0.1])
    blocking = checker.blocked(path, in_the_way, checkpoints=10, margin=0.01)
    assert blocking is not None and blocking['box_id'] == 42 and blocking['checkpoint'] == 0
    assert blocking['distance'] < 0.01 and not blocking['unknown']
    assert checker.blocked(path, far, checkpoints=10, margin=0.01) is None
    with pytest.raises(ValueError, match=r'control_points: shape \(M, 6\)'):
        checker.blocked(np.zeros((2, 5)), far)


def echo_snapshot():
    """The first snapshot `cellmap echo` prints (deltas of the history may come before it)."""
    echo = subprocess.Popen([tool(), 'echo', '--domain', str(DOMAIN), '--cell', CELL, '--timeout', str(PATIENCE)],
                            stdout=subprocess.PIPE, text=True)
    try:
        for line in echo.stdout:
            message = json.loads(line)
            if message['type'] == 'snapshot':
                return message
        raise AssertionError('cellmap echo printed no snapshot')
    finally:
        echo.kill()
        echo.wait()


@pytest.fixture
def daemon():
    os.environ['CYCLONEDDS_URI'] = LOOPBACK
    with tempfile.TemporaryDirectory(prefix='cellmap-python-test-') as folder:
        config = os.path.join(folder, 'cellmapd.yaml')
        with open(config, 'w') as f:
            f.write(f'cell: {CELL}\nsweep_period: 0.2\nstatus_period: 0.5\nsource: {{noise: false}}\n'
                    'change: {settle_sweeps: 4}\n')
        log = open(os.path.join(folder, 'cellmapd.log'), 'w')
        process = subprocess.Popen([os.environ['CELLMAPD'], '--config', config, '--domain', str(DOMAIN),
                                    '--state-dir', os.path.join(folder, 'state')], stdout=log, stderr=log)
        try:
            yield process
        finally:
            process.terminate()
            assert process.wait(timeout=PATIENCE) == 0
            log.close()


def test_the_subscriber_receives_the_versions_and_boxes_echo_receives(daemon):
    changes = []
    with cellmap.EnvironmentSubscriber(domain=DOMAIN, cell=CELL,
                                       on_change=lambda env, delta: changes.append((env.version, delta))) as planner:
        first = planner.wait(timeout=PATIENCE)
        assert first is not None and first.version >= 1 and len(first) > 0
        snapshot = echo_snapshot()
        ours = planner.wait(timeout=PATIENCE, version=snapshot['version'])
        assert ours is not None and ours.version == snapshot['version']
        assert ours.ids.tolist() == [b['id'] for b in snapshot['boxes']]
        assert ours.centers.tolist() == [b['center'] for b in snapshot['boxes']]
        assert ours.half_extents.tolist() == [b['half_extents'] for b in snapshot['boxes']]

        before = planner.environment()
        added = run_tool('inject', '--domain', str(DOMAIN), '--wait', str(PATIENCE), *NEW_BOX).strip()
        assert added
        after = planner.wait(timeout=PATIENCE)
        assert after is not None and after.version > before.version
        version, delta = changes[-1]
        assert version == after.version and delta.to_version == after.version
        new_ids = set(after.ids.tolist()) - set(before.ids.tolist())
        assert new_ids and new_ids <= set(delta.added.tolist()) | set(delta.modified.tolist())
        center = np.array([2.12, 0.45, 0.9])
        assert any(np.all(np.abs(center - c) <= h + 1e-9) for c, h in zip(after.centers, after.half_extents))
        assert planner.stats()['snapshots_applied'] >= 1
        assert planner.last_error() == ''
    with pytest.raises(ValueError, match='closed'):
        planner.environment()


SECURE_DOMAIN = 215
SECURE_LOOPBACK = LOOPBACK.replace('<LeaseDuration>1 s</LeaseDuration>', '')  # DDS Security: Cyclone's 10 s


def test_a_secured_subscriber_joins_with_an_exported_planner_folder(tmp_path):
    os.environ['CYCLONEDDS_URI'] = SECURE_LOOPBACK
    passphrase = tmp_path / 'passphrase'
    passphrase.write_text('a passphrase for the test\n')
    keys, planner = tmp_path / 'keys', tmp_path / 'planner-host'
    run_tool('security', 'init', str(keys), '--cell', CELL, '--domain', str(SECURE_DOMAIN), '--days', '1',
             '--ca-passphrase-file', str(passphrase))
    run_tool('security', 'export', str(keys), '--role', 'planner', '-o', str(planner))
    config = tmp_path / 'cellmapd.yaml'
    config.write_text(f'cell: {CELL}\nsweep_period: 0.2\nstatus_period: 0.5\nsource: {{noise: false}}\n'
                      'change: {settle_sweeps: 4}\n')
    with open(tmp_path / 'cellmapd.log', 'w') as log:
        daemon = subprocess.Popen([os.environ['CELLMAPD'], '--config', str(config), '--domain', str(SECURE_DOMAIN),
                                   '--state-dir', str(tmp_path / 'state'), '--security', str(keys)],
                                  stdout=log, stderr=log)
        try:
            with cellmap.EnvironmentSubscriber(domain=SECURE_DOMAIN, cell=CELL, security=str(planner)) as secured:
                environment = secured.wait(timeout=PATIENCE)
                assert environment is not None and len(environment) > 0
                # Cyclone DDS takes one security setting per domain and process: a plain one is refused here.
                with pytest.raises(cellmap.Error, match='one security setting per domain and process'):
                    cellmap.EnvironmentSubscriber(domain=SECURE_DOMAIN, cell=CELL)
        finally:
            daemon.terminate()
            assert daemon.wait(timeout=PATIENCE) == 0
