// bodypoint view: the page script. `bodypoint view` writes one HTML file holding this script (bundled
// with three.js by esbuild) and the trajectory as JSON in <script id="bodypoint-data">; the page
// needs no server and no network.
//
// Data (written by experiments/cli/view.cpp):
//   { title, scene, revision, centres: [{c: [x,y,z], A}],
//     runs: [{ method, step, bodies: [{ name, steps, force_evals, invariants: {...}, closest: {t, r},
//              frames: { t: [...], R: [x,y,z,...], v: [...], w: [...], dE: [...], dt: [...] },
//              encounter: { R_min, r_min, t_min, asymptotes: [{point, direction, incoming}], deflection },
//              events: [{ label, t, R, r }] }] }] }
// encounter.R_min is the closest approach located on the method's steps (closest.r is only the nearest
// stored state); the asymptotes (one Coulomb centre) are lines the body travels at infinity
// (docs/physics.md, Scattering); events are the hits of `view --event`, located to round-off.
// Frames are decimated by arc length (closest approach kept); the page interpolates linearly in t.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const RUN_COLOURS = [0x2bb3a3, 0xf28e2b];  // run 1, run 2 (--compare)
const BACKGROUND = 0x0d1117;
const PLAY_SECONDS = 20;                  // a whole run at speed 1x
const MIN_MARKER = 0.005;              // smallest marker radius, as a fraction of its distance to the camera
const SPEEDS = [0.1, 0.25, 0.5, 1, 2, 5, 10];

const data = JSON.parse(document.getElementById('bodypoint-data').textContent);

// ---------- page ----------
const style = document.createElement('style');
style.textContent = `
  html, body { margin: 0; height: 100%; background: #0d1117; color: #d8dee9; font: 13px/1.35 system-ui, sans-serif; overflow: hidden; }
  #bp-header { position: absolute; top: 0; left: 0; right: 0; padding: 6px 10px; background: rgba(13,17,23,0.85); z-index: 2; }
  #bp-header b { color: #fff; }
  #bp-header .run { margin-right: 18px; white-space: nowrap; }
  #bp-view { position: absolute; inset: 0; }
  #bp-controls { position: absolute; left: 0; right: 0; bottom: 0; padding: 6px 10px; display: flex; gap: 10px; align-items: center; background: rgba(13,17,23,0.85); z-index: 2; }
  #bp-controls input[type=range] { flex: 1; }
  #bp-controls button, #bp-controls select { background: #222a35; color: #d8dee9; border: 1px solid #3b4452; border-radius: 4px; padding: 2px 8px; }
  #bp-energy { position: absolute; right: 10px; bottom: 44px; background: rgba(13,17,23,0.85); border: 1px solid #3b4452; z-index: 2; }
  #bp-legend { position: absolute; left: 10px; bottom: 44px; padding: 4px 8px; background: rgba(13,17,23,0.85); border: 1px solid #3b4452; z-index: 2; }
  #bp-legend .bar { width: 180px; height: 10px; margin: 3px 0; }
  .swatch { display: inline-block; width: 10px; height: 10px; margin-right: 4px; vertical-align: middle; }
`;
document.head.appendChild(style);

const fmt = (x) => (x === null || x === undefined || !Number.isFinite(x) ? 'n/a' : Math.abs(x) >= 1e-3 && Math.abs(x) < 1e4 ? x.toPrecision(4) : x.toExponential(2));
const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]);
const hex = (c) => '#' + c.toString(16).padStart(6, '0');

const header = document.createElement('div');
header.id = 'bp-header';
let headerHtml = `<b>${esc(data.title)}</b> &nbsp; scene: ${esc(data.scene)}<br>`;
data.runs.forEach((run, k) => {
  const inv = run.bodies.map((b) => {
    const i = b.invariants || {};
    let s = `${esc(b.name)}: max|dE/E| ${fmt(i.max_rel_dE)}, max|dK2²|/K2² ${fmt(i.max_rel_dK2sq)}`;
    if (i.max_abs_dK2Q !== undefined) s += `, max|dK2Q| ${fmt(i.max_abs_dK2Q)}`;
    const located = b.encounter && b.encounter.R_min;  // the header states the located minimum, not a sample's
    s += located ? `, r_min ${fmt(b.encounter.r_min)} at t=${fmt(b.encounter.t_min)}`
      : `, nearest state r ${fmt(b.closest.r)} at t=${fmt(b.closest.t)}`;
    const hits = b.events || [];
    if (hits.length) s += `; ${hits.length} event hit(s): ` + hits.slice(0, 4).map((h) => `${esc(h.label)} at t=${fmt(h.t)}`).join(', ') +
      (hits.length > 4 ? ', ...' : '');
    if (b.outcome && b.outcome !== 'ok') s += ` <b class="flag">${esc(b.outcome)}</b>: ${esc(b.reason)}`;
    return s;
  });
  headerHtml += `<span class="run"><span class="swatch" style="background:${hex(RUN_COLOURS[k])}"></span>` +
    `<b>${esc(run.method)}</b> ${esc(run.step)} &nbsp; ${inv.join('; ')}</span><br>`;
});
header.innerHTML = headerHtml;
document.body.appendChild(header);

const view = document.createElement('div');
view.id = 'bp-view';
document.body.appendChild(view);

const controls = document.createElement('div');
controls.id = 'bp-controls';
controls.innerHTML = `
  <button id="bp-play">Pause</button>
  <label>speed <select id="bp-speed">${SPEEDS.map((s) => `<option value="${s}"${s === 1 ? ' selected' : ''}>${s}x</option>`).join('')}</select></label>
  <input id="bp-time" type="range" min="0" max="10000" step="1" value="0">
  <span id="bp-clock">t = 0</span>
  <button id="bp-reset">Reset view</button>
  <label><input id="bp-follow" type="checkbox"> follow body</label>
  <label>trail <select id="bp-colour"><option value="step">colour: physical step</option><option value="run">colour: run</option></select></label>`;
document.body.appendChild(controls);

const legend = document.createElement('div');
legend.id = 'bp-legend';
document.body.appendChild(legend);

const energy = document.createElement('canvas');
energy.id = 'bp-energy';
energy.width = 300;
energy.height = 150;
document.body.appendChild(energy);

/** A track's colour: its run's, shifted in hue for the second, third, ... body of a scene. */
function trackColour(run, body) {
  const c = new THREE.Color(RUN_COLOURS[run]);
  if (body > 0) c.offsetHSL(0.13 * body, 0, 0.08 * (body % 2 ? 1 : -1));
  return c;
}

// ---------- trajectories ----------
// Every (run, body) pair is one track.
const tracks = [];
data.runs.forEach((run, k) => run.bodies.forEach((b, j) => {
  const f = b.frames;
  tracks.push({ run: k, body: j, name: b.name, t: f.t, R: f.R, v: f.v, w: f.w, dE: f.dE, dt: f.dt, n: f.t.length });
}));
const tMax = Math.max(...tracks.map((tr) => tr.t[tr.n - 1]));
const tMin = Math.min(...tracks.map((tr) => tr.t[0]));

// Bounding box of trails and centres, and the closest approach over all tracks (sizes of markers).
const box = new THREE.Box3();
for (const tr of tracks) for (let i = 0; i < tr.n; ++i) box.expandByPoint(new THREE.Vector3(tr.R[3 * i], tr.R[3 * i + 1], tr.R[3 * i + 2]));
for (const c of data.centres) box.expandByPoint(new THREE.Vector3(...c.c));
const extent = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-9);
const rMin = Math.min(...data.runs.flatMap((run) => run.bodies.map((b) => b.closest.r)));

// Colour map for the physical step: log dt over every track, a perceptual blue-green-yellow ramp.
const RAMP = [[0.267, 0.005, 0.329], [0.229, 0.322, 0.546], [0.128, 0.567, 0.551], [0.369, 0.789, 0.383], [0.993, 0.906, 0.144]];
let dtLo = Infinity, dtHi = -Infinity;
for (const tr of tracks) for (const d of tr.dt) if (d > 0) { dtLo = Math.min(dtLo, d); dtHi = Math.max(dtHi, d); }
function rampColour(x) {
  const u = Math.min(Math.max(x, 0), 1) * (RAMP.length - 1);
  const i = Math.min(Math.floor(u), RAMP.length - 2), f = u - i;
  return RAMP[i].map((a, c) => a + f * (RAMP[i + 1][c] - a));
}
function stepColour(dt) {
  if (!(dtHi > dtLo) || !(dt > 0)) return rampColour(0.5);
  return rampColour(Math.log(dt / dtLo) / Math.log(dtHi / dtLo));
}

// ---------- three.js scene ----------
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(BACKGROUND);
view.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.add(new THREE.AmbientLight(0xffffff, 0.55));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(1, 2, 3);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(45, window.innerWidth / window.innerHeight, extent * 1e-6, extent * 100);
const orbit = new OrbitControls(camera, renderer.domElement);
orbit.enableDamping = false;

// Centres: red attracts (A > 0), blue repels (A < 0); radius grows with |A| and stays below a third of
// the closest approach so the trail never disappears inside a marker.
const aMax = Math.max(...data.centres.map((c) => Math.abs(c.A)), 1e-300);
const centreRadius = Math.min(0.012 * extent, 0.3 * rMin);
const centreMeshes = [];
for (const c of data.centres) {
  const r = Math.max(centreRadius * Math.cbrt(Math.abs(c.A) / aMax), centreRadius * 0.2);
  const m = new THREE.Mesh(new THREE.SphereGeometry(r, 32, 16),
    new THREE.MeshStandardMaterial({ color: c.A > 0 ? 0xe04545 : 0x4a7fe0, emissive: c.A > 0 ? 0x401010 : 0x102040 }));
  m.position.set(...c.c);
  m.userData.radius = r;
  centreMeshes.push(m);
  scene.add(m);
}

// Per track: a faint full path, a trail drawn up to the current time, the body, spin and velocity arrows.
const bodyRadius = Math.min(0.008 * extent, 0.2 * rMin);
for (const tr of tracks) {
  const pos = new Float32Array(tr.R);
  const full = new THREE.BufferGeometry();
  full.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  tr.colour = trackColour(tr.run, tr.body);
  scene.add(new THREE.Line(full, new THREE.LineBasicMaterial({ color: tr.colour, transparent: true, opacity: 0.18 })));

  const trail = new THREE.BufferGeometry();
  trail.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  tr.stepColours = new Float32Array(3 * tr.n);
  tr.runColours = new Float32Array(3 * tr.n);
  const rc = tr.colour;
  for (let i = 0; i < tr.n; ++i) {
    tr.stepColours.set(stepColour(tr.dt[i]), 3 * i);
    tr.runColours.set([rc.r, rc.g, rc.b], 3 * i);
  }
  trail.setAttribute('color', new THREE.BufferAttribute(tr.stepColours.slice(), 3));
  tr.trail = trail;
  scene.add(new THREE.Line(trail, new THREE.LineBasicMaterial({ vertexColors: true })));

  tr.mesh = new THREE.Mesh(new THREE.SphereGeometry(bodyRadius, 24, 12),
    new THREE.MeshStandardMaterial({ color: tr.colour, emissive: 0x202020 }));
  scene.add(tr.mesh);
  tr.spin = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 1, 0x7ee787);
  tr.vel = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 1, 0xf2cc60);
  scene.add(tr.spin, tr.vel);
  tr.wMax = 0; tr.vMax = 0;
  for (let i = 0; i < tr.n; ++i) {
    tr.wMax = Math.max(tr.wMax, Math.hypot(tr.w[3 * i], tr.w[3 * i + 1], tr.w[3 * i + 2]));
    tr.vMax = Math.max(tr.vMax, Math.hypot(tr.v[3 * i], tr.v[3 * i + 1], tr.v[3 * i + 2]));
  }
}

// Encounter marks: the located closest approach (a white wire octahedron) and the incoming and outgoing
// asymptotes as dashed half-lines in the track's colour, from infinity to their closest point to the
// centre and from there on.
const marks = { closest: 0, asymptotes: 0, events: 0 };
for (const tr of tracks) {
  for (const h of data.runs[tr.run].bodies[tr.body].events || []) {  // asked events: a small sphere in the track's colour
    const m = new THREE.Mesh(new THREE.SphereGeometry(1.2 * bodyRadius, 12, 8),
      new THREE.MeshBasicMaterial({ color: tr.colour, wireframe: true }));
    m.position.set(...h.R);
    scene.add(m);
    ++marks.events;
  }
  const e = data.runs[tr.run].bodies[tr.body].encounter;
  if (!e) continue;
  if (e.R_min) {
    const m = new THREE.Mesh(new THREE.OctahedronGeometry(1.8 * bodyRadius),
      new THREE.MeshBasicMaterial({ color: 0xffffff, wireframe: true }));
    m.position.set(...e.R_min);
    scene.add(m);
    ++marks.closest;
  }
  for (const a of e.asymptotes) {
    const p = new THREE.Vector3(...a.point), d = new THREE.Vector3(...a.direction);
    const far = p.clone().addScaledVector(d, a.incoming ? -extent : extent);
    const g = new THREE.BufferGeometry().setFromPoints([far, p]);
    const line = new THREE.Line(g, new THREE.LineDashedMaterial({ color: tr.colour, dashSize: extent / 100,
      gapSize: extent / 100, transparent: true, opacity: 0.7 }));
    line.computeLineDistances();
    scene.add(line);
    ++marks.asymptotes;
  }
}

// ---------- state at time t ----------
function frameIndex(tr, t) {  // last frame with t_i <= t
  let lo = 0, hi = tr.n - 1;
  if (t <= tr.t[0]) return 0;
  if (t >= tr.t[hi]) return hi;
  while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (tr.t[mid] <= t) lo = mid; else hi = mid; }
  return lo;
}
function lerp3(a, i, f) {
  const j = Math.min(i + 1, a.length / 3 - 1);
  return new THREE.Vector3(a[3 * i] + f * (a[3 * j] - a[3 * i]), a[3 * i + 1] + f * (a[3 * j + 1] - a[3 * i + 1]),
    a[3 * i + 2] + f * (a[3 * j + 2] - a[3 * i + 2]));
}
function stateAt(tr, t) {
  const i = frameIndex(tr, t);
  const span = i + 1 < tr.n ? tr.t[i + 1] - tr.t[i] : 0;
  const f = span > 0 ? Math.min(Math.max((t - tr.t[i]) / span, 0), 1) : 0;
  return { i, R: lerp3(tr.R, i, f), v: lerp3(tr.v, i, f), w: lerp3(tr.w, i, f) };
}

let time = tMin, playing = true, speed = 1, follow = false, colourMode = data.runs.length > 1 ? 'run' : 'step';
const slider = document.getElementById('bp-time');
const clock = document.getElementById('bp-clock');
const colourSelect = document.getElementById('bp-colour');
colourSelect.value = colourMode;

function applyColours() {
  for (const tr of tracks) {
    tr.trail.getAttribute('color').array.set(colourMode === 'step' ? tr.stepColours : tr.runColours);
    tr.trail.getAttribute('color').needsUpdate = true;
  }
  if (colourMode === 'step') {
    const stops = [0, 0.25, 0.5, 0.75, 1].map((x) => `rgb(${rampColour(x).map((c) => Math.round(255 * c)).join(',')}) ${100 * x}%`);
    if (!(dtHi > dtLo)) legend.innerHTML = `physical step dt = ${fmt(dtLo)} (fixed)`;
    else legend.innerHTML = `physical step dt along the trail<div class="bar" style="background:linear-gradient(to right,${stops.join(',')})"></div>` +
      `<span>${fmt(dtLo)}</span><span style="float:right">${fmt(dtHi)}</span>`;
  } else {
    legend.innerHTML = tracks.map((tr) => `<span class="swatch" style="background:#${tr.colour.getHexString()}"></span>` +
      `${esc(data.runs[tr.run].method)}${data.runs[tr.run].bodies.length > 1 ? ': ' + esc(tr.name) : ''}`).join('<br>');
  }
  legend.innerHTML += `<br><span class="swatch" style="background:#7ee787"></span>spin w <span class="swatch" style="background:#f2cc60"></span>velocity v`;
}

function update() {
  for (const tr of tracks) {
    const s = stateAt(tr, time);
    tr.trail.setDrawRange(0, s.i + 1);
    tr.mesh.position.copy(s.R);
    tr.current = s;
  }
  if (follow) {
    const target = tracks[0].mesh.position;
    camera.position.add(target.clone().sub(orbit.target));
    orbit.target.copy(target);
  }
  // Markers never shrink below a few pixels, so a body is visible from any distance.
  for (const tr of tracks) tr.mesh.scale.setScalar(Math.max(1, MIN_MARKER * camera.position.distanceTo(tr.mesh.position) / bodyRadius));
  for (const m of centreMeshes) m.scale.setScalar(Math.max(1, MIN_MARKER * camera.position.distanceTo(m.position) / m.userData.radius));
  for (const tr of tracks) {
    // Arrows keep their size on screen: a fixed fraction of the distance to the camera.
    const scale = 0.12 * camera.position.distanceTo(tr.mesh.position);
    for (const [arrow, vec, max] of [[tr.spin, tr.current.w, tr.wMax], [tr.vel, tr.current.v, tr.vMax]]) {
      const len = vec.length();
      arrow.visible = len > 0 && max > 0;
      if (!arrow.visible) continue;
      arrow.position.copy(tr.mesh.position);
      arrow.setDirection(vec.clone().normalize());
      const l = scale * (0.35 + 0.65 * len / max);
      arrow.setLength(l, 0.25 * l, 0.12 * l);
    }
  }
  slider.value = String(Math.round(10000 * (time - tMin) / Math.max(tMax - tMin, 1e-300)));
  clock.textContent = `t = ${time.toFixed(3)} / ${fmt(tMax)}`;
  drawEnergy();
}

// ---------- energy panel: log10 |E - E0|/|E0| against t ----------
function drawEnergy() {
  const g = energy.getContext('2d');
  const W = energy.width, H = energy.height, left = 40, bottom = 18, top = 16;
  g.clearRect(0, 0, W, H);
  g.fillStyle = '#d8dee9';
  g.font = '11px system-ui, sans-serif';
  g.fillText('log10 |E - E0|/|E0|  against t', left, 11);
  let lo = Infinity, hi = -Infinity;
  const floor = 1e-17;
  for (const tr of tracks) for (const e of tr.dE) if (Number.isFinite(e)) { const l = Math.log10(Math.max(e, floor)); lo = Math.min(lo, l); hi = Math.max(hi, l); }
  if (!(hi >= lo)) return;
  if (hi - lo < 1) { hi += 0.5; lo -= 0.5; }
  const x = (t) => left + (W - left - 6) * (t - tMin) / Math.max(tMax - tMin, 1e-300);
  const y = (e) => top + (H - top - bottom) * (hi - Math.log10(Math.max(e, floor))) / (hi - lo);
  g.strokeStyle = '#3b4452';
  g.strokeRect(left, top, W - left - 6, H - top - bottom);
  g.fillText(hi.toFixed(0), 4, top + 8);
  g.fillText(lo.toFixed(0), 4, H - bottom);
  g.fillText(fmt(tMax), W - 40, H - 4);
  for (const tr of tracks) {
    g.strokeStyle = '#' + tr.colour.getHexString();
    g.beginPath();
    for (let i = 0; i < tr.n; ++i) { if (i === 0) g.moveTo(x(tr.t[i]), y(tr.dE[i])); else g.lineTo(x(tr.t[i]), y(tr.dE[i])); }
    g.stroke();
  }
  g.strokeStyle = '#ffffff';
  g.beginPath();
  g.moveTo(x(time), top);
  g.lineTo(x(time), H - bottom);
  g.stroke();
}

function resetView() {
  const centre = box.getCenter(new THREE.Vector3());
  orbit.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(0.25, -0.55, 0.9).normalize().multiplyScalar(1.15 * extent));
  camera.up.set(0, 0, 1);
  orbit.update();
}

// ---------- controls ----------
document.getElementById('bp-play').addEventListener('click', (e) => { playing = !playing; e.target.textContent = playing ? 'Pause' : 'Play'; });
document.getElementById('bp-speed').addEventListener('change', (e) => { speed = Number(e.target.value); });
slider.addEventListener('input', () => { time = tMin + (tMax - tMin) * Number(slider.value) / 10000; update(); });
document.getElementById('bp-reset').addEventListener('click', () => { resetView(); update(); });
document.getElementById('bp-follow').addEventListener('change', (e) => { follow = e.target.checked; update(); });
colourSelect.addEventListener('change', () => { colourMode = colourSelect.value; applyColours(); });
window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

// ---------- animation ----------
let last = null, frames = 0;
function animate(now) {
  if (last !== null && playing) {
    time += (now - last) / 1000 * speed * (tMax - tMin) / PLAY_SECONDS;
    if (time > tMax) time = tMin;
  }
  last = now;
  update();
  orbit.update();
  renderer.render(scene, camera);
  ++frames;
  requestAnimationFrame(animate);
}

let snap = null;
function pixels() {
  const c = document.createElement('canvas');
  c.width = renderer.domElement.width; c.height = renderer.domElement.height;
  const g = c.getContext('2d');
  g.drawImage(renderer.domElement, 0, 0);
  return { data: g.getImageData(0, 0, c.width, c.height).data, w: c.width, h: c.height, scale: c.width / window.innerWidth };
}

// Hooks for the browser test and for scripting the page from the console.
window.bodypointViewer = {
  get ready() { return frames > 0; },
  get frames() { return frames; },
  get time() { return time; },
  tracks: tracks.length,
  /** Encounter marks drawn: located closest approaches and asymptote lines. */
  marks,
  get playing() { return playing; },
  pause() { playing = false; document.getElementById('bp-play').textContent = 'Play'; },
  play() { playing = true; document.getElementById('bp-play').textContent = 'Pause'; },
  /** Screen position (CSS pixels) of track k's body. */
  bodyScreen(k = 0) {
    const p = tracks[k].mesh.position.clone().project(camera);
    return [(p.x + 1) / 2 * window.innerWidth, (1 - p.y) / 2 * window.innerHeight];
  },
  /** Keeps the canvas's current pixels for diffAround. */
  snapshot() { snap = pixels(); },
  /** Mean absolute difference (0..255) between the snapshot and the canvas now, in a box of half-width r CSS px around (x, y). */
  diffAround(x, y, r) {
    const now = pixels(), k = now.scale;
    let sum = 0, n = 0;
    for (let j = Math.max(0, Math.round((y - r) * k)); j < Math.min(now.h, Math.round((y + r) * k)); ++j)
      for (let i = Math.max(0, Math.round((x - r) * k)); i < Math.min(now.w, Math.round((x + r) * k)); ++i) {
        const o = 4 * (j * now.w + i);
        for (let c = 0; c < 3; ++c) sum += Math.abs(now.data[o + c] - snap.data[o + c]);
        n += 3;
      }
    return n ? sum / n : 0;
  },
  /** Pixel statistics of the 3D canvas: mean and standard deviation of the luminance, fraction not background. */
  canvasStats() {
    const px = pixels().data;
    // The background is the most common colour (the clear colour after the browser's colour management).
    const counts = new Map();
    for (let i = 0; i < px.length; i += 4 * 97) {
      const key = (px[i] << 16) | (px[i + 1] << 8) | px[i + 2];
      counts.set(key, (counts.get(key) || 0) + 1);
    }
    let bgKey = 0, best = -1;
    for (const [k, c] of counts) if (c > best) { best = c; bgKey = k; }
    const bg = [(bgKey >> 16) & 255, (bgKey >> 8) & 255, bgKey & 255];
    let sum = 0, sum2 = 0, other = 0;
    const n = px.length / 4;
    for (let i = 0; i < px.length; i += 4) {
      const l = 0.299 * px[i] + 0.587 * px[i + 1] + 0.114 * px[i + 2];
      sum += l; sum2 += l * l;
      if (Math.abs(px[i] - bg[0]) + Math.abs(px[i + 1] - bg[1]) + Math.abs(px[i + 2] - bg[2]) > 24) ++other;
    }
    const mean = sum / n;
    return { mean, std: Math.sqrt(Math.max(sum2 / n - mean * mean, 0)), nonBackground: other / n, background: bg };
  },
};

resetView();
applyColours();
update();
requestAnimationFrame(animate);
