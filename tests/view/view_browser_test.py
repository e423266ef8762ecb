#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`cellmap view` in a real browser: cellmapd on the simulated cell (exact depths), `cellmap view`, `cellmap
inject` and `cellmap render` as processes, and Debian's chromium (headless) driven by python3-selenium. At the
end cellmapd runs the arm cell (its fixed camera only) on the same domain, to see the robot layer move.

Domain 220. CELLMAP_BROWSER_ROUNDS=N repeats the inject/remove/restart
round N times (default 1, the CI run). The last screenshot is written to view_browser.png in the working
directory (the build's tests folder under ctest).
"""
import argparse
import base64
import io
import os
import queue
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest

from PIL import Image
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By

# Cyclone DDS on loopback only, as tests/transport/loopback.hpp (1 s lease: a killed daemon is noticed soon).
LOOPBACK = ('<CycloneDDS><Domain Id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/>'
            '</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>'
            '<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>30</MaxAutoParticipantIndex>'
            '<Peers><Peer address="127.0.0.1"/></Peers><LeaseDuration>1 s</LeaseDuration></Discovery>'
            '</Domain></CycloneDDS>')
PATIENCE = 90  # seconds; passing runs take a few, the machine is shared
LIVE_DOMAIN = 220
BACKGROUND = (0xfb, 0xfc, 0xfd)  # the scene's background colour in view.js
TABLE_POINT = (1.0, 1.25, 0.75)  # on the default cell's table top, clear of every object (config/cell.yaml)
NEW_BOX = ['add-box', '--center', '2.12,0.45,0.9', '--half-extents', '0.1,0.1,0.15']  # the README's example
NEW_BOX_TOP = (2.12, 0.45, 1.05)
NEW_BOX_CENTER = (2.12, 0.45, 0.9)
ARM_BASE = (1.5, -0.45, 0.5)  # where config/scenes/arm_cell.yaml stands the arm's base_link
# A cell id anyone on the domain could publish (and a config may hold): markup that runs script if the page
# ever put it into its HTML unescaped.
HOSTILE_CELL = '<img src=x onerror="window.injected=1">'
# Unknown space is tracked under the table's front edge only, where no camera of the gantry looks (the table top
# is between them and it) and the page's camera sees it below the table's edge: one unknown box, clear of every
# obstacle box.
UNKNOWN_LOWER = (1.0, 0.1, 0.1)
UNKNOWN_UPPER = (2.0, 0.6, 0.6)

ARGS = None


class Process:
    """A child process whose stdout lines are collected by a thread; stderr goes to a log file."""

    def __init__(self, argv, log_path):
        self.log_path = log_path
        self.log = open(log_path, 'ab')
        self.popen = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=self.log, env=os.environ)
        self.lines = queue.Queue()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.popen.stdout:
            self.lines.put(line.decode(errors='replace').rstrip('\n'))

    def line(self, timeout=PATIENCE):
        return self.lines.get(timeout=timeout)

    def stop(self, sig=signal.SIGTERM):
        if self.popen.poll() is None:
            self.popen.send_signal(sig)
        code = self.popen.wait(timeout=PATIENCE)
        self.reader.join(timeout=PATIENCE)
        self.popen.stdout.close()
        self.log.close()
        return code

    def log_text(self):
        with open(self.log_path, 'rb') as f:
            return f.read().decode(errors='replace')


def wait_for(predicate, what, timeout=PATIENCE):
    """Polls `predicate` (an observable state of a process or the page) until it is truthy."""
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        try:
            last = predicate()
            if last:
                return last
        except Exception as e:  # the page may be between two states (an element being replaced)
            last = repr(e)
        time.sleep(0.1)
    raise AssertionError(f'timed out after {timeout} s waiting for {what} (last: {last})')


def free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def run_tool(*args):
    out = subprocess.run([ARGS.cellmap, *args], capture_output=True, text=True, timeout=PATIENCE)
    if out.returncode != 0:
        raise AssertionError(f'cellmap {" ".join(args)} failed: {out.stderr.strip()}')
    return out.stdout.strip()


def start_browser(profile):
    options = webdriver.ChromeOptions()
    options.binary_location = '/usr/bin/chromium'
    for flag in ['--headless=new', '--no-sandbox', '--disable-gpu', '--disable-background-networking',
                 '--disable-component-update', '--disable-sync', '--no-first-run', '--window-size=1280,800',
                 f'--user-data-dir={profile}']:
        options.add_argument(flag)
    return webdriver.Chrome(service=Service('/usr/bin/chromedriver'), options=options)


class ViewTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.environ['CYCLONEDDS_URI'] = LOOPBACK
        cls.dir = tempfile.mkdtemp(prefix='cellmap-view-test-')
        cls.browser = start_browser(os.path.join(cls.dir, 'chromium'))

    @classmethod
    def tearDownClass(cls):
        cls.browser.quit()
        shutil.rmtree(cls.dir, ignore_errors=True)

    def setUp(self):
        self.processes = []
        self.started = time.monotonic()

    def log(self, text):
        print(f'[{time.monotonic() - self.started:6.1f} s] {text}', flush=True)

    def tearDown(self):
        for p in self.processes:
            if not p.log.closed:
                p.stop(signal.SIGKILL)

    # ---- processes ----
    def start_daemon(self, text=None, name='cellmapd'):
        config = os.path.join(self.dir, f'{name}.yaml')
        with open(config, 'w') as f:
            # Exact depths fill the map in two sweeps: a short settling is enough.
            f.write(text or 'cell: cell-view\nsweep_period: 0.2\nstatus_period: 0.5\nsource: {noise: false}\n'
                            'change: {settle_sweeps: 4}\n'
                            f'unknown: {{workspace: {{lower: {list(UNKNOWN_LOWER)}, upper: {list(UNKNOWN_UPPER)}}}}}\n')
        daemon = Process([ARGS.cellmapd, '--config', config, '--domain', str(LIVE_DOMAIN), '--state-dir',
                          os.path.join(self.dir, f'{name}-state')], os.path.join(self.dir, f'{name}.log'))
        self.processes.append(daemon)
        return daemon

    def start_view(self, domain, port):
        view = Process([ARGS.cellmap, 'view', '--domain', str(domain), '--port', str(port)],
                       os.path.join(self.dir, f'view-{domain}.log'))
        self.processes.append(view)
        line = view.line()
        self.assertRegex(line, rf'^cellmap view: http://127\.0\.0\.1:{port}/ \(DDS domain {domain}, every cell; '
                               r'read-only\)$')
        return view

    # ---- what the page shows ----
    def js(self, expression):
        return self.browser.execute_script(f'return {expression};')

    def box_count(self):
        return int(self.browser.find_element(By.ID, 'box-count').text)

    def listed_ids(self):
        return self.js('[...document.querySelectorAll("#boxes tbody tr")].map((row) => Number(row.dataset.id))')

    def notice(self):
        element = self.browser.find_element(By.ID, 'notice')
        return element.text if element.is_displayed() else ''

    def daemon_state(self):
        elements = self.browser.find_elements(By.ID, 'daemon-state')
        return elements[0].text if elements else ''

    def daemon_snapshot(self):
        """(version, boxes) of the daemon's current snapshot, read by `cellmap render --domain`."""
        out = run_tool('render', '--domain', str(LIVE_DOMAIN), '--no-robot', '--timeout', '60', '-o',
                       os.path.join(self.dir, 'render.png'))
        match = re.match(r'^wrote .*: cell cell-view, version (\d+), (\d+) boxes(?: \(\d+ unknown\))?$', out)
        self.assertIsNotNone(match, out)
        return int(match.group(1)), int(match.group(2))

    def wait_for_daemon_snapshot(self, what):
        """The page comes to show the daemon's version and box count (exact depths: no version comes by
        itself meanwhile), in the header, the list and the scene."""
        version, boxes = self.daemon_snapshot()
        wait_for(lambda: self.js('cellmapView.version()') == version and self.box_count() == boxes ==
                 len(self.listed_ids()) == len(self.js('cellmapView.boxIds()')), what)

    def check_screenshot(self):
        png = self.browser.get_screenshot_as_png()
        with open('view_browser.png', 'wb') as f:
            f.write(png)
        image = Image.open(io.BytesIO(png)).convert('RGB')
        ratio = self.js('window.devicePixelRatio')
        x, y = self.js('cellmapView.project(%f, %f, %f)' % TABLE_POINT)
        pixel = image.getpixel((int(x * ratio), int(y * ratio)))
        difference = sum(abs(a - b) for a, b in zip(pixel, BACKGROUND))
        self.assertGreater(difference, 30, f'the table at ({x:.0f}, {y:.0f}) is drawn as {pixel}: background')

    # ---- the tests ----
    def test_live_view_follows_the_daemon(self):
        port = free_port()
        view = self.start_view(LIVE_DOMAIN, port)
        # Boxes glow for 4 s by default; long enough here that a loaded machine cannot miss it.
        self.browser.get(f'http://127.0.0.1:{port}/?highlight=60')
        self.browser.execute_script('window.notReloaded = true;')
        wait_for(lambda: self.js('cellmapView.connected()'), 'the page to connect')
        self.assertIn(f'No cellmapd on DDS domain {LIVE_DOMAIN}', wait_for(self.notice, 'the page to say so'))
        self.assertEqual(self.box_count(), 0)
        self.log('the page says there is no daemon')

        daemon = self.start_daemon()
        wait_for(lambda: self.js('cellmapView.version()') >= 1, 'the first version on the page')
        self.log('the first version is on the page')
        self.wait_for_daemon_snapshot('the page to show the daemon\'s boxes')
        self.log(f'the page shows version {self.js("cellmapView.version()")}, {self.box_count()} boxes')
        self.assertEqual(self.notice(), '')
        self.assertEqual(wait_for(self.daemon_state, 'the daemon state'), 'running')
        self.check_screenshot()
        self.check_unknown()
        rounds = int(os.environ.get('CELLMAP_BROWSER_ROUNDS', '1'))
        for round_number in range(rounds):
            daemon, view = self.round(daemon, view, port, round_number)
        self.check_layers(daemon)
        self.check_sensors(daemon)
        self.assertEqual(daemon.stop(), 0)
        self.check_robot()
        self.check_hostile_cell()
        self.assertTrue(self.js('window.notReloaded === true'), 'the page was reloaded')

    def round(self, daemon, view, port, round_number):
        before = self.listed_ids()
        if round_number == 0:
            self.browser.find_element(By.ID, 'layer-regions').click()
        # Watched while the tool still runs: the box glows for a few seconds only.
        inject = Process([ARGS.cellmap, 'inject', '--domain', str(LIVE_DOMAIN), '--wait', '60', *NEW_BOX],
                         os.path.join(self.dir, 'inject.log'))
        # Count, list and the rows marked as changed in one look (the glow lasts a few seconds).
        shown = wait_for(lambda: self.js(
            '(() => { const n = Number(document.getElementById("box-count").textContent);'
            f' if (n !== {len(before) + 1}) return null;'
            ' const rows = [...document.querySelectorAll("#boxes tbody tr")];'
            ' return { listed: rows.map((r) => Number(r.dataset.id)),'
            '          changed: rows.filter((r) => r.classList.contains("changed")).map((r) => Number(r.dataset.id)) };'
            ' })()'), 'the new box on the page')
        added = sorted(set(shown['listed']) - set(before))
        self.assertEqual(len(added), 1, f'listed {shown["listed"]}, before {before}')
        new_id = added[0]
        self.assertIn(new_id, shown['changed'])
        wait_for(lambda: new_id in self.js('cellmapView.highlighted()'), 'the new box to glow in the scene')
        self.report_latency()
        if round_number == 0:
            self.check_regions(daemon)
        self.check_click(new_id)
        self.check_screenshot()
        name = inject.line()
        self.assertEqual(inject.stop(), 0)

        run_tool('inject', '--domain', str(LIVE_DOMAIN), '--wait', '60', 'remove', '--name', name)
        wait_for(lambda: self.box_count() == len(before), 'the box to go')
        self.log(f'box {new_id} removed')
        self.assertNotIn(new_id, self.listed_ids())
        self.assertNotIn(new_id, self.js('cellmapView.boxIds()'))

        # The daemon restarts: the page says it is gone, then recovers by itself.
        version = self.js('cellmapView.version()')
        self.assertEqual(daemon.stop(), 0)
        wait_for(lambda: 'is gone' in self.browser.find_element(By.ID, 'banner').text, 'the page to say so')
        self.assertEqual(self.box_count(), len(before))  # the last version stays shown
        daemon = self.start_daemon()
        wait_for(lambda: self.daemon_state() == 'running', 'the restarted daemon on the page')
        self.wait_for_daemon_snapshot('the page to show the restarted daemon\'s boxes')
        self.assertGreaterEqual(self.js('cellmapView.version()'), version)
        self.log('the page recovered from the daemon restart')

        # The viewer restarts: the page reconnects by itself.
        self.assertEqual(view.stop(), 0)
        wait_for(lambda: not self.js('cellmapView.connected()'), 'the page to notice')
        view = self.start_view(LIVE_DOMAIN, port)
        wait_for(lambda: self.js('cellmapView.connected()'), 'the page to reconnect')
        wait_for(lambda: self.box_count() == len(before) == len(self.js('cellmapView.boxIds()')),
                 'the page to show the boxes again')
        self.log(f'round {round_number + 1}: box {new_id} added and removed, daemon and viewer restarted')
        return daemon, view

    def check_unknown(self):
        """The unknown box under the table is drawn grey where nothing is in front of it (its front face, seen
        below the table's edge), goes when "unknown space" is unticked and comes back with the key U."""
        ids = wait_for(lambda: self.js('cellmapView.unknownIds()'), 'an unknown box on the page')
        self.assertEqual(len(ids), 1, ids)
        box = self.js(f'cellmapView.box({ids[0]})')
        self.assertEqual(box['space'], 'unknown')
        self.assertIn('unknown', self.browser.find_element(By.ID, 'help').text)
        self.assertIn('1 of them unknown space', self.browser.find_element(By.TAG_NAME, 'header').text)
        lower = [c - h for c, h in zip(box['center'], box['half_extents'])]
        upper = [c + h for c, h in zip(box['center'], box['half_extents'])]
        for lo, hi, want_lo, want_hi in zip(lower, upper, UNKNOWN_LOWER, UNKNOWN_UPPER):
            self.assertTrue(want_lo - 0.05 <= lo < hi <= want_hi + 0.05, box)  # the workspace, to a voxel or two
        # Points on the front face (y = lower y), away from its dashed edges and the table above.
        front = [(lower[0] + fx * (upper[0] - lower[0]), lower[1], lower[2] + fz * (upper[2] - lower[2]))
                 for fx in (0.2, 0.35, 0.5, 0.65, 0.8) for fz in (0.2, 0.35, 0.5, 0.65)]
        samples = self.pixels(front)
        checkbox = self.browser.find_element(By.ID, 'show-unknown')
        self.assertTrue(checkbox.is_selected())

        def greyed(shown, hidden):
            """How many samples are a neutral grey, darker than the same pixel without the unknown box."""
            return sum(1 for x, y in samples if is_unknown_grey(shown.getpixel((x, y)), hidden.getpixel((x, y))))

        shown = self.screenshot()
        checkbox.click()
        wait_for(lambda: self.js('cellmapView.unknownShown().length === 0'), 'the unknown box hidden')
        hidden = wait_for(lambda: (lambda h: h if greyed(shown, h) >= 0.8 * len(samples) else None)(
            self.screenshot()), 'the unknown box to go from the canvas')
        self.log(f'{greyed(shown, hidden)} of {len(samples)} points of the unknown box\'s front face drawn grey, '
                 'gone when unticked')
        ActionChains(self.browser).send_keys('u').perform()
        wait_for(lambda: self.js('cellmapView.unknownShown().length === 1'), 'the key U to show it again')
        self.assertTrue(checkbox.is_selected())
        again = wait_for(lambda: (lambda a: a if greyed(a, hidden) >= 0.8 * len(samples) else None)(
            self.screenshot()), 'the unknown box drawn again')
        self.log(f'{greyed(again, hidden)} of {len(samples)} points grey again after the key U')

    def check_click(self, box_id):
        """A click on the new box's top shows its details."""
        canvas = self.browser.find_element(By.ID, 'canvas')
        left, top, width, height = self.js('(() => { const r = document.getElementById("canvas")'
                                           '.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()')
        x, y = self.js('cellmapView.project(%s, %s, %s)' % NEW_BOX_TOP)
        ActionChains(self.browser).move_to_element_with_offset(
            canvas, int(x - left - width / 2), int(y - top - height / 2)).click().perform()
        text = wait_for(lambda: self.browser.find_element(By.ID, 'selection').text, 'the box details')
        self.assertIn(f'box {box_id}\n', text)
        self.assertIn(f'changed in version {self.js("cellmapView.version()")}', text)
        size = re.search(r'size ([\d.]+) × ([\d.]+) × ([\d.]+) m', text)
        self.assertIsNotNone(size, text)
        for edge in size.groups():  # the injected box is 0.2 × 0.2 × 0.3 m; boxes grow by up to a voxel
            self.assertTrue(0.15 < float(edge) < 0.4, text)

    def report_latency(self):
        """The newest version is drawn in a frame after its message came; logs how long each step took (a
        measurement, not a bound: a loaded machine or a slow GPU emulation may take seconds)."""
        last = wait_for(lambda: self.js('(() => { const l = cellmapView.latency[cellmapView.latency.length - 1];'
                                        ' return l && l.frame_ms !== null ? l : null; })()'),
                        'the newest version to be drawn')
        stamp_to_message = last['message_ms'] - last['stamp_ns'] / 1e6
        message_to_frame = last['frame_ms'] - last['message_ms']
        self.log(f'version {last["version"]}: daemon stamp -> page message {stamp_to_message:.1f} ms, '
                 f'message -> drawn frame {message_to_frame:.1f} ms')
        self.assertGreaterEqual(message_to_frame, 0)

    def check_layers(self, daemon):
        """Ticking a layer makes the daemon publish it; unticking stops it."""
        self.browser.find_element(By.ID, 'layer-voxels').click()
        wait_for(lambda: 'layer voxels: 1 reader(s)' in daemon.log_text(), 'the daemon to publish voxels')
        runs = wait_for(lambda: self.js('(() => { const m = window.cellmapView; return m && '
                                        'document.getElementById("layer-voxels").checked && '
                                        'm.voxelRuns(); })()'), 'voxels on the page')
        self.assertGreater(runs, 100)
        self.check_screenshot()
        self.browser.find_element(By.ID, 'layer-voxels').click()
        wait_for(lambda: 'layer voxels: no reader' in daemon.log_text(), 'the daemon to stop publishing')


    def check_sensors(self, daemon):
        """Ticking "sensors" makes the daemon publish its frames' poses and fields of view, and the page draws
        each frustum: along the lines from each sensor, pixels turn the frustum colour."""
        before = self.screenshot()
        self.browser.find_element(By.ID, 'layer-sensors').click()
        logged = wait_for(lambda: re.search(r'layer sensors: (\d+) views, (\d+) bytes', daemon.log_text()),
                          'the daemon to publish the sensor views')
        views, size = int(logged.group(1)), int(logged.group(2))
        self.log(f'sensor layer: {views} views, {size} bytes per sweep')
        self.assertGreater(views, 0)
        segments = wait_for(lambda: (lambda s: s if len(s) == views else None)(self.js('cellmapView.sensorSegments()')),
                            'the sensor views on the page')
        ratio = self.js('window.devicePixelRatio')
        samples = []
        for segment in segments:
            self.assertIsNotNone(segment, 'a simulated camera knows its field of view')
            origin, end = segment
            # The upper part of each line: above every object of the default cell, so nothing hides it.
            for t in [0.05 + 0.3 * i / 9 for i in range(10)]:
                point = [o + t * (e - o) for o, e in zip(origin, end)]
                x, y = self.js('cellmapView.project(%f, %f, %f)' % tuple(point))
                samples.append((int(x * ratio), int(y * ratio)))

        def drawn_fraction():
            after = self.screenshot()
            hits = sum(1 for x, y in samples if colour_near(before, after, x, y, is_frustum_colour))
            return hits / len(samples)
        fraction = wait_for(lambda: (lambda f: f if f >= 0.8 else None)(drawn_fraction()),
                            'the frustum lines drawn')
        self.log(f'{fraction:.0%} of {len(samples)} points along the frustum lines drawn in its colour')
        self.browser.find_element(By.ID, 'layer-sensors').click()
        wait_for(lambda: 'layer sensors: no reader' in daemon.log_text(), 'the daemon to stop publishing')


    def screenshot(self):
        return Image.open(io.BytesIO(self.browser.get_screenshot_as_png())).convert('RGB')

    def pixels(self, points):
        """Where cell-frame points appear in a screenshot (device pixels)."""
        ratio = self.js('window.devicePixelRatio')
        return [(int(x * ratio), int(y * ratio))
                for x, y in (self.js('cellmapView.project(%f, %f, %f)' % tuple(p)) for p in points)]

    def check_regions(self, daemon):
        """The sweep that confirmed the new box sent its change region: the page draws a region around the box,
        its top edges in the region colour, gone when the layer is unticked."""
        logged = wait_for(lambda: re.search(r'layer change regions: (\d+) regions, (\d+) bytes', daemon.log_text()),
                          'the daemon to publish the change regions')
        self.log(f'change regions layer: {logged.group(1)} regions, {logged.group(2)} bytes')

        def around_new_box():
            return [r for r in self.js('cellmapView.regionBounds()')
                    if all(lo <= c <= hi for lo, c, hi in zip(r[0], NEW_BOX_CENTER, r[1]))]
        region = wait_for(around_new_box, 'a change region around the new box on the page')[0]
        (x0, y0, _), (x1, y1, z1) = region
        self.assertLess(x1 - x0, 0.6, region)  # the 0.2 m box and its margin, not the whole cell
        corners = [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
        edges = [[[a + t / 10 * (b - a) for a, b in zip(corners[i], corners[(i + 1) % 4])] for t in range(1, 10)]
                 for i in range(4)]
        samples = self.pixels([p for edge in edges for p in edge])
        shown = self.screenshot()
        self.browser.find_element(By.ID, 'layer-regions').click()
        wait_for(lambda: self.js('cellmapView.regionBounds().length === 0'), 'the regions to go from the page')
        hidden = self.screenshot()
        hits = sum(1 for x, y in samples if colour_near(hidden, shown, x, y, is_region_colour))
        self.log(f'{hits} of {len(samples)} points along the region\'s top edges drawn in its colour')
        self.assertGreaterEqual(hits, 0.6 * len(samples))
        wait_for(lambda: 'layer change regions: no reader' in daemon.log_text(), 'the daemon to stop publishing')

    def check_robot(self):
        """cellmapd on the arm cell: ticking "robot" draws the arm's links, its base where the scene stands it,
        and the links move with the arm's joints from sweep to sweep."""
        scene = os.path.join(ARGS.config_dir, 'scenes', 'arm_cell.yaml')
        daemon = self.start_daemon(f'cell: arm-view\nsweep_period: 0.5\nstatus_period: 0.5\n'
                                   f'sources:\n  - {{kind: sim, scene: {scene}, sensor: post}}\n', 'arm')
        select = wait_for(lambda: (lambda o: o if 'arm-view' in o else None)(
            [o.text for o in self.browser.find_elements(By.CSS_SELECTOR, '#cell-select option')]),
            'the arm cell in the list of cells')
        self.browser.find_element(By.CSS_SELECTOR, '#cell-select option[value="arm-view"]').click()
        wait_for(lambda: self.js('cellmapView.cell()') == 'arm-view', 'the page to show the arm cell')
        self.log('arm cell shown')
        before = self.canvas()[1]
        self.browser.find_element(By.ID, 'layer-robot').click()
        logged = wait_for(lambda: re.search(r'layer robot: (\d+) shapes \((\d+) triangles\), (\d+) bytes',
                                            daemon.log_text()), 'the daemon to publish the robot')
        self.log(f'robot layer: {logged.group(1)} shapes, {logged.group(2)} triangles, {logged.group(3)} bytes '
                 f'per sweep (cells listed: {select})')
        first = self.drawn_robot(before)
        base = next(s for s in first['shapes'] if s['link'] == 'base_link')
        for got, want in zip(base['position'], ARM_BASE):
            self.assertAlmostEqual(got, want, delta=1e-6)
        tool = lambda robot: next(s for s in robot['shapes'] if s['link'] == 'link_6')['center']
        second = wait_for(lambda: (lambda r: r if r['sweep'] > first['sweep'] and
                                   max(abs(a - b) for a, b in zip(tool(r), tool(first))) > 0.05 else None)(
            self.drawn_robot(before)), 'the arm to move on the page')
        moved = [b - a for a, b in zip(tool(first), tool(second))]
        self.log(f'sweeps {first["sweep"]} -> {second["sweep"]}: link_6 moved by '
                 f'({moved[0]:.3f}, {moved[1]:.3f}, {moved[2]:.3f}) m, drawn at its place each time')
        self.check_rendered_robot(int(logged.group(1)))
        self.browser.find_element(By.ID, 'layer-robot').click()
        wait_for(lambda: 'layer robot: no reader' in daemon.log_text(), 'the daemon to stop publishing')
        self.assertEqual(daemon.stop(), 0)
        self.log('arm cell daemon stopped')

    def check_hostile_cell(self):
        """A daemon whose cell id is markup: the page lists and shows the id as text, and no element of it
        appears in the page, nor does its script run."""
        daemon = self.start_daemon(f"cell: '{HOSTILE_CELL}'\nsweep_period: 0.5\nstatus_period: 0.5\n", 'hostile')
        options = wait_for(lambda: (lambda o: o if HOSTILE_CELL in o else None)(
            [o.text for o in self.browser.find_elements(By.CSS_SELECTOR, '#cell-select option')]),
            'the hostile cell id in the list of cells, as text')
        option = next(o for o in self.browser.find_elements(By.CSS_SELECTOR, '#cell-select option')
                      if o.get_attribute('value') == HOSTILE_CELL)
        option.click()
        wait_for(lambda: self.js('cellmapView.cell()') == HOSTILE_CELL, 'the page to show the hostile cell')
        shown = wait_for(lambda: (lambda t: t if HOSTILE_CELL in t else None)(
            self.browser.find_element(By.TAG_NAME, 'body').text), 'the cell id shown as text')
        self.assertEqual(self.js('document.querySelectorAll("img").length'), 0, 'markup from the network in the page')
        self.assertIsNone(self.js('window.injected'), 'script from the network ran')
        self.log(f'hostile cell id listed among {len(options)} cells and shown as text '
                 f'({shown.count(HOSTILE_CELL)} times), no element made of it')
        self.assertEqual(daemon.stop(), 0)

    def check_rendered_robot(self, shapes):
        """`cellmap render --domain` draws the arm cell's robot from its layer: every shape, in the robot's
        colour, next to the boxes."""
        png = os.path.join(self.dir, 'arm.png')
        out = run_tool('render', '--domain', str(LIVE_DOMAIN), '--cell', 'arm-view', '--timeout', '60', '-o', png)
        match = re.match(r'^wrote .*: cell arm-view, version \d+, \d+ boxes( \(\d+ unknown\))?, '
                         r'the robot \((\d+) shapes\)$', out)
        self.assertIsNotNone(match, out)
        self.assertEqual(int(match.group(2)), shapes)
        image = Image.open(png).convert('RGB')
        orange = sum(1 for p in image.getdata() if is_robot_colour(p))
        self.log(f'cellmap render drew the robot: {shapes} shapes, {orange} pixels in its colour')
        self.assertGreater(orange, 2000)

    def canvas(self):
        """The robot as in the last frame the page drew, and that frame (read together, in one script)."""
        robot, url = self.js('[cellmapView.robot(), document.getElementById("canvas").toDataURL("image/png")]')
        return robot, Image.open(io.BytesIO(base64.b64decode(url.split(',', 1)[1]))).convert('RGB')

    def drawn_robot(self, before):
        """The robot as the page draws it: the centre of every link's drawn bounds is in the robot colour (where
        it was not before the layer was shown)."""
        def look():
            robot, frame = self.canvas()
            if not robot or not robot['shapes']:
                return None
            drawn = [s['link'] for s in robot['shapes']
                     if colour_near(before, frame, int(s['pixel'][0]), int(s['pixel'][1]), is_robot_colour, 3)]
            return robot if len(drawn) >= len(robot['shapes']) - 1 else None  # one may hide behind another
        return wait_for(look, 'the robot drawn')


def colour_near(before, after, x, y, is_colour, radius=2):
    """Whether a pixel within `radius` of (x, y) is of a colour (`is_colour`) and was not before."""
    for dx in range(-radius, radius + 1):
        for dy in range(-radius, radius + 1):
            p = (x + dx, y + dy)
            if not (0 <= p[0] < after.width and 0 <= p[1] < after.height):
                continue
            if is_colour(after.getpixel(p)) and after.getpixel(p) != before.getpixel(p):
                return True
    return False


def is_unknown_grey(shown, hidden):
    """Unknown space's grey (kUnknownColour, faint over what is behind): a neutral grey, every channel at least
    15 darker than the same pixel with the unknown box hidden (the light background, or a grid line)."""
    return max(shown) - min(shown) <= 10 and all(h - s >= 15 for s, h in zip(shown, hidden))


def is_region_colour(pixel):
    """The change regions' magenta (0xe0399a), antialiased over the light background."""
    r, g, b = pixel
    return r - g > 60 and b - g > 25


def is_robot_colour(pixel):
    """The robot's orange (0xf07818), shaded (faces turned down from the light are dark)."""
    r, g, b = pixel
    return r > 70 and r - b > 60 and r - g > 25 and g > b


def is_frustum_colour(pixel):
    """The frustum's teal (0x008c8c), antialiased over the light background: green and blue well above red."""
    r, g, b = pixel
    return g - r > 40 and b - r > 40 and abs(g - b) < 50


def main():
    global ARGS
    parser = argparse.ArgumentParser()
    parser.add_argument('--cellmap', required=True)
    parser.add_argument('--cellmapd', required=True)
    parser.add_argument('--config-dir', required=True)  # the repository's config/, for the arm cell
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0], '-v', *rest])


if __name__ == '__main__':
    main()
