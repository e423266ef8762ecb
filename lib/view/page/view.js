// SPDX-License-Identifier: Apache-2.0
// cellmap view: the cell's boxes in 3D, kept live over a WebSocket from `cellmap view` (the protocol is
// described in cellmap/view/view_state.hpp). Read-only: the page only asks to see things.
import * as THREE from '/three/build/three.module.js';
import { OrbitControls } from '/three/examples/jsm/controls/OrbitControls.js';

// How long boxes of the latest version glow (the page's ?highlight=SECONDS changes it) and a removed box stays
// as a red outline; both fade out over their last FADE_MS.
const HIGHLIGHT_MS = 1000 * (Number(new URLSearchParams(location.search).get('highlight')) || 4);
const GHOST_MS = 3000;
const FADE_MS = 1500;
const TIMELINE_SHOWN = 200;
const BOX_OPACITY = 0.88;
// Unknown boxes (space no sensor has observed) are large and may hold obstacles: a faint grey fill that never
// hides what is inside or behind it, and dashed edges, so they never read as an obstacle.
const UNKNOWN_COLOUR = new THREE.Color(0.55, 0.55, 0.55);  // kUnknownColour in cellmap/boxes/box.hpp
const UNKNOWN_OPACITY = 0.3;
const UNKNOWN_EDGE_COLOUR = 0x6b6b6b;
const FADE_STEP_MS = 250;

const $ = (id) => document.getElementById(id);

// ---- what the server told us ----
const cells = new Map();  // name → {name, version, stamp_ns, boxes: Map(id → box), timeline: [], status}
let domain = null;
let cellFilter = '';
let selectedCell = null;  // the cell shown
let selectedBox = null;   // the box id clicked
let socket = null;
let connected = false;
const latency = [];  // per version received: stamp, receive, message and frame times (ms since the epoch)
let pendingFrameStamps = [];

// ---- the 3D scene (cell frame: z up) ----
const canvas = $('canvas');
// Without WebGL the page still lists boxes, versions and status, and says why the scene is missing.
let renderer = null;
let drawingProblem = '';
try {
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
} catch (e) {
  drawingProblem = `This browser cannot draw the scene (WebGL: ${e.message}); the lists on the right stay live.`;
}
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xfbfcfd);
const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 200);
camera.up.set(0, 0, 1);
camera.position.set(-2.5, -3.5, 3.0);
const controls = new OrbitControls(camera, canvas);
controls.addEventListener('change', requestRender);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 0.75));
const sun = new THREE.DirectionalLight(0xffffff, 0.55);
sun.position.set(-3, -4, 8);
scene.add(sun);
const grid = new THREE.GridHelper(10, 20, 0xb9c2ca, 0xdde2e6);
grid.rotation.x = Math.PI / 2;  // GridHelper lies in x-z; the cell's floor is x-y
scene.add(grid);
scene.add(new THREE.AxesHelper(0.5));
const boxGroup = new THREE.Group();
const ghostGroup = new THREE.Group();
const layerGroup = new THREE.Group();
scene.add(boxGroup, ghostGroup, layerGroup);

const meshes = new Map();      // box id → {mesh, edges}
const highlights = new Map();  // box id → time (performance.now) the highlight ends
const ghosts = [];             // {object, until}
let fittedCell = null;

// Same hue formula as `cellmap render` (golden-ratio steps around the circle).
function boxColour(id) {
  const hue = ((id % 1000003) * 0.618033988749895) % 1.0;
  return new THREE.Color().setHSL(hue, 0.62, 0.66);
}

function isUnknown(box) {
  return box.space === 'unknown';
}

// The fill of a box: its id's hue, or the one grey of unknown space.
function fillColour(box) {
  return isUnknown(box) ? UNKNOWN_COLOUR.clone() : boxColour(box.id);
}

function boxOpacity(box) {
  if (isUnknown(box)) return UNKNOWN_OPACITY;
  return $('layer-voxels').checked ? 0.25 : BOX_OPACITY;
}

function edgeColour(box) {
  return isUnknown(box) ? UNKNOWN_EDGE_COLOUR : 0x2a3440;
}

function makeBoxObject(box) {
  const size = box.half_extents.map((h) => Math.max(2 * h, 1e-4));
  const geometry = new THREE.BoxBufferGeometry(size[0], size[1], size[2]);
  const unknown = isUnknown(box);
  // An unknown box writes no depth, so obstacles inside or behind it are drawn whatever the order.
  const material = new THREE.MeshLambertMaterial({ color: fillColour(box), transparent: true,
                                                    opacity: boxOpacity(box), depthWrite: !unknown });
  const mesh = new THREE.Mesh(geometry, material);
  const edges = new THREE.LineSegments(
    new THREE.EdgesGeometry(geometry),
    unknown ? new THREE.LineDashedMaterial({ color: edgeColour(box), dashSize: 0.06, gapSize: 0.04 })
            : new THREE.LineBasicMaterial({ color: edgeColour(box) }));
  if (unknown) edges.computeLineDistances();
  mesh.add(edges);
  mesh.visible = !unknown || $('show-unknown').checked;
  mesh.position.set(box.center[0], box.center[1], box.center[2]);
  const [w, x, y, z] = box.rotation;
  mesh.quaternion.set(x, y, z, w);
  mesh.userData.id = box.id;
  return { mesh, edges, box };
}

function disposeObject(object) {
  object.traverse((o) => {
    if (o.geometry) o.geometry.dispose();
    if (o.material) o.material.dispose();
  });
}

function removeMesh(id) {
  const entry = meshes.get(id);
  if (!entry) return;
  boxGroup.remove(entry.mesh);
  disposeObject(entry.mesh);
  meshes.delete(id);
}

function putMesh(box) {
  removeMesh(box.id);
  const entry = makeBoxObject(box);
  boxGroup.add(entry.mesh);
  meshes.set(box.id, entry);
}

function addGhost(box) {
  const size = box.half_extents.map((h) => Math.max(2 * h, 1e-4));
  const geometry = new THREE.BoxBufferGeometry(size[0], size[1], size[2]);
  const ghost = new THREE.LineSegments(new THREE.EdgesGeometry(geometry),
                                       new THREE.LineBasicMaterial({ color: 0xd03030, transparent: true }));
  geometry.dispose();
  ghost.position.set(box.center[0], box.center[1], box.center[2]);
  const [w, x, y, z] = box.rotation;
  ghost.quaternion.set(x, y, z, w);
  ghostGroup.add(ghost);
  ghosts.push({ object: ghost, until: performance.now() + GHOST_MS });
}

function rebuildScene() {
  for (const id of [...meshes.keys()]) removeMesh(id);
  const cell = cells.get(selectedCell);
  if (cell) for (const box of cell.boxes.values()) putMesh(box);
  if (cell && cell.boxes.size > 0 && fittedCell !== selectedCell) {
    fitCamera(cell);
    fittedCell = selectedCell;
  }
  rebuildLayers();
  requestRender();
}

function fitCamera(cell) {
  const bounds = new THREE.Box3();
  for (const entry of meshes.values()) bounds.expandByObject(entry.mesh);
  if (bounds.isEmpty()) return;
  const centre = bounds.getCenter(new THREE.Vector3());
  const radius = bounds.getSize(new THREE.Vector3()).length() / 2;
  controls.target.copy(centre);
  const direction = new THREE.Vector3(-0.55, -0.75, 0.62).normalize();
  camera.position.copy(centre).addScaledVector(direction, radius * 2.4);
  camera.near = radius / 100;
  camera.far = radius * 20;
  camera.updateProjectionMatrix();
  grid.position.set(Math.round(centre.x), Math.round(centre.y), 0);
  controls.update();
}

// ---- highlights: the boxes of the latest version glow, then fade ----
const highlightColour = new THREE.Color(0xff8a00);
const selectedColour = new THREE.Color(0x1e5bc6);

// Glow strength 1 until the last FADE_MS, then fading to 0; returns when the scene must be drawn again
// (ms from now), or null when nothing glows.
function applyHighlights(now) {
  let next = null;
  const wake = (ms) => { next = next === null ? ms : Math.min(next, ms); };
  const strength = (until) => {
    if (until > now + FADE_MS) wake(until - FADE_MS - now);
    else if (until > now) wake(FADE_STEP_MS);
    return Math.min(1, Math.max(0, (until - now) / FADE_MS));
  };
  for (const [id, entry] of meshes) {
    const until = highlights.get(id);
    const left = until ? strength(until) : 0;
    const selected = id === selectedBox;
    entry.glow = left;
    // An unknown box keeps its grey fill (a glow would give it an obstacle's hue); its edges glow.
    const glowFill = isUnknown(entry.box) ? 0 : left;
    entry.mesh.material.color.copy(fillColour(entry.box)).lerp(highlightColour, glowFill);
    // A glowing box stays orange when selected; its blue edges show the selection.
    entry.mesh.material.emissive.copy(glowFill > 0 ? highlightColour : selectedColour)
      .multiplyScalar(glowFill > 0 ? 0.35 * glowFill : selected ? 0.45 : 0);
    entry.edges.material.color.set(selected ? 0x1565c0 : left > 0 ? 0xd35400 : edgeColour(entry.box));
  }
  for (const [id, until] of highlights) if (until <= now) highlights.delete(id);
  for (let i = ghosts.length - 1; i >= 0; --i) {
    const left = strength(ghosts[i].until);
    if (left <= 0) {
      ghostGroup.remove(ghosts[i].object);
      disposeObject(ghosts[i].object);
      ghosts.splice(i, 1);
    } else {
      ghosts[i].object.material.opacity = left;
    }
  }
  return next;
}

// ---- drawing on demand: a frame when something changed, and while highlights fade ----
let frameRequested = false;
let drawnRobot = null;  // the robot layer's group in the last frame drawn

function requestRender() {
  if (frameRequested) return;
  frameRequested = true;
  requestAnimationFrame(drawFrame);
}

function drawFrame() {
  frameRequested = false;
  if (!renderer) return;
  resize();
  const now = performance.now();
  const redraw = applyHighlights(now);
  renderer.render(scene, camera);
  drawnRobot = layerGroup.children.find((o) => o.userData.robot !== undefined) || null;
  if (pendingFrameStamps.length > 0) {
    const drawn = Date.now();
    for (const entry of pendingFrameStamps) entry.frame_ms = drawn;
    pendingFrameStamps = [];
  }
  // A glow is drawn once, then a few frames a second while it fades: a browser drawing in software (no GPU)
  // stays responsive.
  if (redraw !== null) setTimeout(requestRender, redraw);
  updateBoxTable(false);
}

function resize() {
  const width = canvas.clientWidth;
  const height = canvas.clientHeight;
  if (canvas.width !== Math.floor(width * renderer.getPixelRatio()) ||
      canvas.height !== Math.floor(height * renderer.getPixelRatio())) {
    renderer.setSize(width, height, false);
    camera.aspect = width / Math.max(height, 1);
    camera.updateProjectionMatrix();
  }
}
window.addEventListener('resize', requestRender);

// ---- picking: a click (not a drag) on a box shows its details ----
const raycaster = new THREE.Raycaster();
let pointerDown = null;
canvas.addEventListener('pointerdown', (e) => { pointerDown = { x: e.clientX, y: e.clientY }; });
canvas.addEventListener('pointerup', (e) => {
  if (!pointerDown || Math.hypot(e.clientX - pointerDown.x, e.clientY - pointerDown.y) > 4) return;
  const rect = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1,
                                -((e.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  // An obstacle inside or behind an unknown box is what a click there means; an unknown box only where no
  // obstacle is hit. Hidden boxes are not clickable.
  const shown = [...meshes.values()].filter((m) => m.mesh.visible);
  const hitOf = (entries) => raycaster.intersectObjects(entries.map((m) => m.mesh), false)[0];
  const hit = hitOf(shown.filter((m) => !isUnknown(m.box))) || hitOf(shown.filter((m) => isUnknown(m.box)));
  selectBox(hit ? hit.object.userData.id : null);
});

function selectBox(id) {
  selectedBox = id;
  showSelection();
  updateBoxTable(true);
  requestRender();
}

function fmt(x, digits = 3) {
  return Number(x).toFixed(digits);
}

function eulerDegrees(rotation) {
  const [w, x, y, z] = rotation;
  const e = new THREE.Euler().setFromQuaternion(new THREE.Quaternion(x, y, z, w), 'ZYX');
  return [e.x, e.y, e.z].map((a) => fmt((a * 180) / Math.PI, 1));
}

function changedIn(cell, box) {
  if (box.changed_in !== null && box.changed_in !== undefined) return `version ${box.changed_in}`;
  return `≤ ${cell.joined_at} (before the viewer joined)`;
}

function showSelection() {
  const panel = $('selection');
  const cell = cells.get(selectedCell);
  const box = cell && selectedBox !== null ? cell.boxes.get(selectedBox) : null;
  if (!box) {
    panel.hidden = true;
    return;
  }
  const size = box.half_extents.map((h) => fmt(2 * h));
  const [roll, pitch, yaw] = eulerDegrees(box.rotation);
  const what = isUnknown(box) ? ' <span class="unknown-tag">unknown space</span>' : '';
  panel.innerHTML = `<h3>box ${box.id}${what}</h3><table>
    <tr><td>size</td><td>${size.join(' × ')} m</td></tr>
    <tr><td>centre</td><td>${box.center.map((c) => fmt(c)).join(', ')} m</td></tr>
    <tr><td>rotation</td><td>[${box.rotation.map((q) => fmt(q, 4)).join(', ')}]<br>
        roll ${roll}° pitch ${pitch}° yaw ${yaw}°</td></tr>
    <tr><td>${isUnknown(box) ? 'unknown voxels' : 'points'}</td><td>${box.points}</td></tr>
    <tr><td>changed in</td><td>${changedIn(cell, box)}</td></tr></table>`;
  panel.hidden = false;
}

// ---- the side bar and the header ----
// Text from the network (cell ids, states, sensor names) as HTML text, never as markup.
function escapeHtml(text) {
  return String(text).replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);
}

function stampText(ns) {
  if (!ns) return '';
  const d = new Date(ns / 1e6);
  return d.toLocaleTimeString([], { hour12: false }) + '.' + String(d.getMilliseconds()).padStart(3, '0');
}

function updateHeader() {
  const cell = cells.get(selectedCell);
  $('version').textContent = cell && cell.version > 0 ? cell.version : '–';
  $('stamp').textContent = cell && cell.stamp_ns ? stampText(cell.stamp_ns) : '';
  $('box-count').textContent = cell ? cell.boxes.size : 0;
  const unknown = cell ? [...cell.boxes.values()].filter(isUnknown).length : 0;
  $('unknown-count').textContent = unknown;
  $('unknown-figure').hidden = unknown === 0;
  const select = $('cell-select');
  const names = [...cells.keys()].sort();
  if (select.options.length !== names.length || names.some((n, i) => select.options[i].value !== n)) {
    select.innerHTML = names.map((n) => `<option value="${escapeHtml(n)}">${escapeHtml(n)}</option>`).join('');
  }
  select.value = selectedCell || '';
  select.hidden = names.length < 2;
}

function updateStatus() {
  const cell = cells.get(selectedCell);
  const status = cell ? cell.status : null;
  const badge = $('daemon-badge');
  const list = $('status');
  if (!status) {
    badge.hidden = true;
    list.innerHTML = '<dt>daemon</dt><dd>none reporting</dd>';
    return;
  }
  badge.hidden = false;
  badge.textContent = status.daemon ? `cellmapd ${status.state}` : 'no cellmapd';
  badge.className = 'badge ' + (!status.daemon ? 'bad' : status.state === 'running' ? 'ok' : 'warn');
  const sensors = status.sensors.map((s) => `${escapeHtml(s.name)}: ${escapeHtml(s.state)}`).join('<br>') || '–';
  const lastSweep = status.last_sweep_ns ? stampText(status.last_sweep_ns) : '–';
  list.innerHTML = `
    <dt>daemon</dt><dd id="daemon-state">${escapeHtml(status.daemon ? status.state : `gone (last: ${status.state})`)}</dd>
    <dt>cell</dt><dd>${escapeHtml(status.cell)}</dd>
    <dt>sensors</dt><dd>${sensors}</dd>
    <dt>sweeps</dt><dd id="sweeps">${status.sweeps}</dd>
    <dt>last sweep</dt><dd>${lastSweep}</dd>
    <dt>dropped frames</dt><dd>${status.dropped_frames}</dd>
    <dt>version</dt><dd>${status.version} (${status.boxes} boxes)</dd>`;
}

function updateTimeline() {
  const cell = cells.get(selectedCell);
  const list = $('timeline');
  if (!cell) {
    list.innerHTML = '';
    return;
  }
  const rows = [];
  const entries = cell.timeline.slice(-TIMELINE_SHOWN).reverse();
  entries.forEach((e, i) => {
    let jump = '';
    if (e.from_version === 0 && e.to_version > 1) jump = ' (viewer joined)';
    else if (e.to_version - e.from_version > 1) jump = ` (from ${e.from_version})`;
    rows.push(`<li class="${i === 0 ? 'latest' : ''}">v${e.to_version}${jump} ${stampText(e.stamp_ns)} ` +
              `<span class="added">+${e.added}</span> <span class="modified">~${e.modified}</span> ` +
              `<span class="removed">−${e.removed}</span></li>`);
  });
  list.innerHTML = rows.join('');
}

let tableShown = '';
function updateBoxTable(force) {
  const cell = cells.get(selectedCell);
  const boxes = cell ? [...cell.boxes.values()].sort((a, b) => a.id - b.id) : [];
  const key = boxes.map((b) => `${b.id}:${b.changed_in}:${highlights.has(b.id)}`).join(',') + '|' + selectedBox +
              '|' + $('show-unknown').checked;
  if (!force && key === tableShown) return;
  tableShown = key;
  $('boxes').tBodies[0].innerHTML = boxes.map((b) => {
    const size = b.half_extents.map((h) => Math.round(200 * h)).join('×');
    const classes = [highlights.has(b.id) ? 'changed' : '', b.id === selectedBox ? 'selected' : '',
                     isUnknown(b) ? 'unknown' : '', isUnknown(b) && !$('show-unknown').checked ? 'hidden-box' : '']
      .join(' ');
    const swatch = `<span class="swatch${isUnknown(b) ? ' unknown' : ''}" ` +
                   `style="background:#${fillColour(b).getHexString()}"></span>`;
    return `<tr data-id="${b.id}" class="${classes.replace(/ +/g, ' ').trim()}"><td>${swatch}${b.id}</td>` +
           `<td>${size}${isUnknown(b) ? ' <span class="unknown-tag">unknown</span>' : ''}</td>` +
           `<td>${b.points}</td><td>${b.changed_in ?? '≤ ' + cell.joined_at}</td></tr>`;
  }).join('');
}
$('boxes').tBodies[0].addEventListener('click', (e) => {
  const row = e.target.closest('tr');
  if (row) selectBox(Number(row.dataset.id));
});

// What the scene area says instead of showing an empty or stale cell.
function updateNotice() {
  const notice = $('notice');
  const banner = $('banner');
  const cell = cells.get(selectedCell);
  let text = '';
  let bannerText = '';
  const where = `DDS domain ${domain}` + (cellFilter ? ` (cell ${cellFilter})` : '');
  if (drawingProblem) {
    text = drawingProblem;
  } else if (!connected) {
    text = 'The viewer server is not reachable; retrying…';
    if (cell && cell.version > 0) {
      text = '';
      bannerText = 'Viewer server unreachable; retrying… (showing the last version received)';
    }
  } else if (!cell || !cell.status) {
    if (!cell || cell.version === 0) text = `No cellmapd on ${where}. Waiting for one to start…`;
    else bannerText = `No cellmapd reporting for cell ${cell.name}; showing version ${cell.version}.`;
  } else if (!cell.status.daemon) {
    if (cell.version === 0) text = `No cellmapd on ${where}. Waiting for one to start…`;
    else bannerText = `cellmapd of cell ${cell.name} is gone; showing its last version, ${cell.version}.`;
  } else if (cell.version === 0) {
    text = `cellmapd of cell ${cell.name} is ${cell.status.state}; waiting for its first version ` +
           `(the map settles first)…`;
  }
  notice.textContent = text;
  notice.hidden = text === '';
  banner.textContent = bannerText;
  banner.hidden = bannerText === '';
}

function updateAll() {
  if (!selectedCell || !cells.has(selectedCell)) selectedCell = [...cells.keys()].sort()[0] || null;
  updateHeader();
  updateStatus();
  updateTimeline();
  updateBoxTable(true);
  updateNotice();
  showSelection();
}

$('cell-select').addEventListener('change', (e) => {
  selectedCell = e.target.value;
  selectedBox = null;
  highlights.clear();
  rebuildScene();
  updateAll();
});

// ---- messages from the server ----
function newCell(name) {
  return { name, version: 0, stamp_ns: 0, joined_at: 0, boxes: new Map(), timeline: [], status: null,
           voxels: null, regions: null, sensors: null, robot: null };
}

function onState(message) {
  domain = message.domain;
  cellFilter = message.cell_filter;
  const layers = new Map([...cells].map(([name, c]) => [name, { voxels: c.voxels, regions: c.regions,
                                                                   sensors: c.sensors, robot: c.robot }]));
  cells.clear();
  for (const c of message.cells) {
    const cell = newCell(c.cell);
    cell.version = c.version;
    cell.stamp_ns = c.stamp_ns;
    cell.joined_at = c.timeline.length > 0 ? c.timeline[0].to_version : c.version;
    for (const box of c.boxes) cell.boxes.set(box.id, box);
    cell.timeline = c.timeline;
    cell.status = c.status;
    Object.assign(cell, layers.get(c.cell) || {});
    cells.set(c.cell, cell);
  }
  updateAll();
  rebuildScene();
}

function onVersion(m) {
  let cell = cells.get(m.cell);
  if (!cell) {
    cell = newCell(m.cell);
    cells.set(m.cell, cell);
  }
  if (m.to_version <= cell.version) return;  // already in the state this page got
  if (m.from_version !== cell.version) {
    send({ type: 'resync' });  // a version went missing between server and page
    return;
  }
  if (cell.version === 0) cell.joined_at = m.to_version;
  const shown = m.cell === selectedCell || !selectedCell;
  const until = performance.now() + HIGHLIGHT_MS;
  for (const id of m.removed) {
    const box = cell.boxes.get(id);
    if (shown && box) addGhost(box);
    cell.boxes.delete(id);
    if (shown) removeMesh(id);
    if (selectedBox === id) selectedBox = null;
  }
  for (const box of [...m.added, ...m.modified]) {
    cell.boxes.set(box.id, box);
    // A first copy of a cell already running is no change; its version 1 is.
    if (shown && (m.from_version !== 0 || m.to_version === 1)) highlights.set(box.id, until);
  }
  cell.version = m.to_version;
  cell.stamp_ns = m.stamp_ns;
  cell.timeline.push({ from_version: m.from_version, to_version: m.to_version, stamp_ns: m.stamp_ns,
                       received_ns: m.received_ns, added: m.added.length, modified: m.modified.length,
                       removed: m.removed.length });
  const entry = { version: m.to_version, stamp_ns: m.stamp_ns, received_ns: m.received_ns,
                  message_ms: Date.now(), frame_ms: null };
  latency.push(entry);
  if (latency.length > 1000) latency.shift();
  updateAll();
  if (shown) {
    const first = document.querySelector('#boxes tr.changed');
    if (first) first.scrollIntoView({ block: 'nearest' });
    for (const box of [...m.added, ...m.modified]) putMesh(box);
    if (fittedCell !== selectedCell && cell.boxes.size > 0) rebuildScene();
    pendingFrameStamps.push(entry);
    requestRender();
  }
}

function onStatus(m) {
  let cell = cells.get(m.cell);
  if (!cell) {
    cell = newCell(m.cell);
    cells.set(m.cell, cell);
  }
  cell.status = m;
  if (!selectedCell) updateAll();
  else if (m.cell === selectedCell) {
    updateStatus();
    updateNotice();
  } else updateHeader();
}

function onLayer(m) {
  const cell = cells.get(m.cell);
  if (!cell) return;
  cell[m.type] = m;
  if (m.cell === selectedCell) rebuildLayers();
}

// ---- optional layers ----
function rebuildLayers() {
  for (const child of [...layerGroup.children]) {
    layerGroup.remove(child);
    disposeObject(child);
  }
  const cell = cells.get(selectedCell);
  if (!cell) return;
  const voxels = $('layer-voxels').checked && cell.voxels;
  for (const entry of meshes.values()) {
    entry.mesh.material.opacity = isUnknown(entry.box) ? UNKNOWN_OPACITY : voxels ? 0.25 : BOX_OPACITY;
  }
  if (voxels) layerGroup.add(voxelObject(cell.voxels));
  if ($('layer-regions').checked && cell.regions) layerGroup.add(regionObject(cell.regions));
  if ($('layer-sensors').checked && cell.sensors) layerGroup.add(sensorObject(cell.sensors));
  if ($('layer-robot').checked && cell.robot) layerGroup.add(robotObject(cell.robot));
  requestRender();
}

// One instance per run of voxels along x: a settled cell is a few thousand instances.
function voxelObject(layer) {
  const runs = layer.runs;
  const count = runs.length / 4;
  const r = layer.resolution;
  const mesh = new THREE.InstancedMesh(new THREE.BoxBufferGeometry(1, 1, 1),
                                       new THREE.MeshLambertMaterial({ color: 0x3d6a9e }), count);
  const matrix = new THREE.Matrix4();
  const position = new THREE.Vector3();
  const scale = new THREE.Vector3();
  const rotation = new THREE.Quaternion();
  for (let i = 0; i < count; ++i) {
    const [x, y, z, length] = runs.slice(4 * i, 4 * i + 4);
    position.set((x + length / 2) * r, (y + 0.5) * r, (z + 0.5) * r);
    scale.set(length * r, r, r);
    mesh.setMatrixAt(i, matrix.compose(position, rotation, scale));
  }
  mesh.instanceMatrix.needsUpdate = true;
  mesh.raycast = () => {};  // clicks go to the boxes
  return mesh;
}

function regionObject(layer) {
  const group = new THREE.Group();
  for (const region of layer.regions) {
    const size = [0, 1, 2].map((i) => region.max[i] - region.min[i]);
    const geometry = new THREE.BoxBufferGeometry(size[0], size[1], size[2]);
    const lines = new THREE.LineSegments(new THREE.EdgesGeometry(geometry),
                                         new THREE.LineBasicMaterial({ color: 0xe0399a }));
    geometry.dispose();
    lines.position.set(...[0, 1, 2].map((i) => (region.max[i] + region.min[i]) / 2));
    group.add(lines);
  }
  group.userData.regions = layer.regions.map((region) => [region.min, region.max]);
  return group;
}

// Each frame's sensor: a small axes cross at its pose, and its field of view as lines from the sensor out to
// its range or to the floor (z = 0), whichever is nearer; a camera's far corners joined into its frustum.
const SENSOR_COLOUR = 0x008c8c;

function sensorObject(layer) {
  const group = new THREE.Group();
  const material = new THREE.LineBasicMaterial({ color: SENSOR_COLOUR });
  const segments = [];  // per view: [origin, end of the first ray] in the cell frame, for tests
  for (const view of layer.views) {
    const origin = new THREE.Vector3(...view.position);
    const [w, x, y, z] = view.rotation;
    const rotation = new THREE.Quaternion(x, y, z, w);
    const axes = new THREE.AxesHelper(0.1);
    axes.position.copy(origin);
    axes.quaternion.copy(rotation);
    group.add(axes);
    const ends = view.outline.map((ray) => {
      const direction = new THREE.Vector3(...ray).applyQuaternion(rotation);
      const toFloor = direction.z < 0 ? -origin.z / direction.z : Infinity;
      return origin.clone().addScaledVector(direction, Math.min(view.max_range, toFloor));
    });
    const points = [];
    for (const end of ends) points.push(origin, end);
    for (let i = 0; i + 1 < ends.length; ++i) points.push(ends[i], ends[i + 1]);
    if (view.closed && ends.length > 2) points.push(ends[ends.length - 1], ends[0]);
    if (points.length > 0) {
      group.add(new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(points), material));
    }
    segments.push(ends.length > 0 ? [origin, ends[0]] : null);
  }
  group.userData.segments = segments;
  return group;
}

// The robot's collision shapes where it was at the latest sweep, solid, in one colour (a carried payload in
// another); they are not clickable. The self filter cuts them out grown by the layer's padding.
const ROBOT_COLOUR = 0xf07818;
const PAYLOAD_COLOUR = 0x8a5a2b;

function shapeGeometry(shape) {
  if (shape.kind === 'box') {
    const [x, y, z] = shape.half_extents.map((h) => 2 * h);
    return new THREE.BoxBufferGeometry(x, y, z);
  }
  if (shape.kind === 'cylinder') {
    const geometry = new THREE.CylinderBufferGeometry(shape.radius, shape.radius, 2 * shape.half_length, 24);
    return geometry.rotateX(Math.PI / 2);  // three.js cylinders stand along y, the shape's along its z
  }
  if (shape.kind === 'sphere') return new THREE.SphereBufferGeometry(shape.radius, 24, 16);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(shape.vertices, 3));
  geometry.setIndex(shape.triangles);
  geometry.computeVertexNormals();
  return geometry;
}

function robotObject(layer) {
  const group = new THREE.Group();
  for (const shape of layer.shapes) {
    const material = new THREE.MeshLambertMaterial({ color: shape.carried ? PAYLOAD_COLOUR : ROBOT_COLOUR,
                                                     side: THREE.DoubleSide });  // meshes' winding varies
    const mesh = new THREE.Mesh(shapeGeometry(shape), material);
    mesh.position.set(...shape.position);
    const [w, x, y, z] = shape.rotation;
    mesh.quaternion.set(x, y, z, w);
    mesh.userData.robotShape = { link: shape.link, carried: shape.carried };
    mesh.raycast = () => {};  // clicks go to the boxes
    group.add(mesh);
  }
  group.userData.robot = layer.sweep;
  return group;
}

function sendLayers() {
  send({ type: 'layers', voxels: $('layer-voxels').checked, regions: $('layer-regions').checked,
         sensors: $('layer-sensors').checked, robot: $('layer-robot').checked });
  rebuildLayers();
}
for (const name of ['voxels', 'regions', 'sensors', 'robot']) $(`layer-${name}`).addEventListener('change', sendLayers);

// ---- unknown space: shown or hidden in this page only (the daemon publishes it either way) ----
function showUnknown() {
  const shown = $('show-unknown').checked;
  for (const entry of meshes.values()) if (isUnknown(entry.box)) entry.mesh.visible = shown;
  if (!shown && selectedBox !== null && meshes.has(selectedBox) && isUnknown(meshes.get(selectedBox).box)) {
    selectBox(null);
  }
  updateBoxTable(true);
  requestRender();
}
$('show-unknown').addEventListener('change', showUnknown);
// The key U does what the checkbox does (the help line says so), unless typing goes somewhere else.
window.addEventListener('keydown', (e) => {
  if (e.key !== 'u' && e.key !== 'U') return;
  const target = e.target;
  const typing = target.isContentEditable || ['SELECT', 'TEXTAREA'].includes(target.tagName) ||
                 (target.tagName === 'INPUT' && target.type !== 'checkbox');
  if (e.ctrlKey || e.metaKey || e.altKey || typing) return;
  $('show-unknown').checked = !$('show-unknown').checked;
  showUnknown();
});

// ---- the WebSocket: reconnects by itself, and the server sends the whole state on each connection ----
let retryMs = 500;

function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
}

function setConnection(text, kind) {
  const badge = $('connection');
  badge.textContent = text;
  badge.className = 'badge ' + kind;
}

function connect() {
  const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
  socket = new WebSocket(`${scheme}://${location.host}/ws`);
  socket.onopen = () => {
    connected = true;
    retryMs = 500;
    setConnection('live', 'ok');
    sendLayers();
  };
  socket.onmessage = (event) => {
    const message = JSON.parse(event.data);
    if (message.type === 'state') onState(message);
    else if (message.type === 'version') onVersion(message);
    else if (message.type === 'status') onStatus(message);
    else if (['voxels', 'regions', 'sensors', 'robot'].includes(message.type)) onLayer(message);
  };
  socket.onclose = () => {
    if (connected) setConnection('reconnecting', 'bad');
    connected = false;
    updateNotice();
    setTimeout(connect, retryMs);
    retryMs = Math.min(retryMs * 2, 2000);
  };
}

// For tests and the curious: what the page shows, read from the scene itself.
window.cellmapView = {
  connected: () => connected,
  cell: () => selectedCell,
  version: () => (cells.get(selectedCell) || { version: 0 }).version,
  boxIds: () => [...meshes.keys()].sort((a, b) => a - b),
  // The unknown boxes in the scene, and those of them shown (not hidden by the checkbox or the key U).
  unknownIds: () => [...meshes.keys()].filter((id) => isUnknown(meshes.get(id).box)).sort((a, b) => a - b),
  unknownShown: () => [...meshes.keys()].filter((id) => isUnknown(meshes.get(id).box) && meshes.get(id).mesh.visible)
    .sort((a, b) => a - b),
  // A box as the page holds it (id, center, half_extents, rotation, points, space, changed_in), or null.
  box: (id) => { const entry = meshes.get(id); return entry ? entry.box : null; },
  highlighted: () => [...meshes.keys()].filter((id) => meshes.get(id).glow > 0),  // as in the last frame drawn
  voxelRuns: () => layerGroup.children.filter((o) => o.isInstancedMesh).reduce((n, o) => n + o.count, 0),
  // The sweep of the latest layer ("voxels", "regions", "sensors" or "robot") of the shown cell, or null.
  layerSweep: (type) => ((cells.get(selectedCell) || {})[type] || { sweep: null }).sweep,
  // Where a point of the cell frame appears in the page (CSS pixels from the top left of the document).
  project: (x, y, z) => {
    const p = new THREE.Vector3(x, y, z).project(camera);
    const rect = canvas.getBoundingClientRect();
    return [rect.left + ((p.x + 1) / 2) * rect.width, rect.top + ((1 - p.y) / 2) * rect.height];
  },
  // The sensor views drawn: per view, its origin and the end of its first ray as drawn (cell frame), or null.
  sensorSegments: () => {
    const group = layerGroup.children.find((o) => o.userData.segments);
    return group ? group.userData.segments.map((s) => s && s.map((p) => [p.x, p.y, p.z])) : [];
  },
  // The change regions drawn: per region, its min and max corners (cell frame).
  regionBounds: () => layerGroup.children.filter((o) => o.userData.regions).flatMap((o) => o.userData.regions),
  // The robot as in the last frame drawn (what the canvas shows): its sweep and per shape its link, whether
  // carried, its frame's origin and the centre of its bounds (cell frame), and where that centre is on the
  // canvas (device pixels from its top left).
  robot: () => {
    if (!drawnRobot) return null;
    const shapes = drawnRobot.children.map((m) => {
      const center = new THREE.Box3().setFromObject(m).getCenter(new THREE.Vector3());
      const p = center.clone().project(camera);
      return { ...m.userData.robotShape, position: m.position.toArray(), center: center.toArray(),
               pixel: [((p.x + 1) / 2) * canvas.width, ((1 - p.y) / 2) * canvas.height] };
    });
    return { sweep: drawnRobot.userData.robot, shapes };
  },
  latency,
};

updateAll();
requestRender();
connect();
