// The animation page's drawing code. Everything it shows comes from the data the walker
// binary computed (the key points' floor-frame positions per frame, from the engine's forward
// kinematics); this file only decodes and draws them. The page API for tests and scripts:
// window.walker = { ready, error, duration_s, frames, floorLevels, frameTime(i), seek(t_s), play(),
// pause(), time() }.
import * as THREE from "three";

const data = JSON.parse(document.getElementById("walker-data").textContent);
const api = window.walker;

function bytes(b64) {
  const s = atob(b64);
  const out = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
  return out.buffer;
}
// Little-endian arrays (as the binary wrote them; every browser's typed arrays are too).
const tr = data.track;
const times = new Float32Array(bytes(tr.t_s));
// Step of each frame as people number it (from 1, computed by the binary).
const stepNumber = new Uint16Array(bytes(tr.step_number));
const origin = new Float32Array(bytes(tr.origin_m));
const rel = new Int16Array(bytes(tr.rel));
const K = tr.points;
// The stored point of each key point the parts name (shared rod ends are stored once).
const pointOf = tr.point_of;
const N = tr.frames;
const duration = times[N - 1];

// Scene, lights, camera.
const canvas = document.getElementById("view");
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f6f8);
scene.add(new THREE.HemisphereLight(0xffffff, 0x99a0aa, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(2, 5, 3);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 500);
const controls = new THREE.OrbitControls(camera, canvas);
controls.enableDamping = false;

// The floor frame (x forward down the slope, y normal to the floor, z to the right), turned
// so that gravity points down the screen.
const world = new THREE.Group();
world.rotation.z = data.world_rotation_z_rad;
scene.add(world);

// Floor: a plane and a grid over the walk's extent, and the path of the hip on it.
let lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
for (let i = 0; i < N; i++) {
  lo = [Math.min(lo[0], origin[3 * i]), Math.min(lo[1], origin[3 * i + 2])];
  hi = [Math.max(hi[0], origin[3 * i]), Math.max(hi[1], origin[3 * i + 2])];
}
const span = Math.ceil(Math.max(hi[0] - lo[0], hi[1] - lo[1]) + 16);
const cx = (lo[0] + hi[0]) / 2, cz = (lo[1] + hi[1]) / 2;
const floor = new THREE.Mesh(
  new THREE.PlaneGeometry(span, span),
  new THREE.MeshStandardMaterial({ color: 0xdfe3e8, side: THREE.DoubleSide, roughness: 1 }),
);
floor.rotation.x = -Math.PI / 2;
floor.position.set(cx, -0.0005, cz);
// A floor that steps up or down (walker walk --floor): a terrace under each step, at its
// stance foot's level, instead of the plane and the grid.
const terraces = data.floor_levels || [];
const levelOfStep = new Map(terraces.map((t) => [t.step, t.y_m]));
if (terraces.length > 0) {
  const terraceMaterial = new THREE.MeshStandardMaterial({
    color: 0xdfe3e8, side: THREE.DoubleSide, roughness: 1,
  });
  const edgeMaterial = new THREE.LineBasicMaterial({ color: 0x7a838d });
  const edgeLine = (x0, y0, x1, y1) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(new Float32Array([
      x0, y0, cz - span / 2, x0, y0, cz + span / 2, x1, y1, cz + span / 2, x1, y1, cz - span / 2,
      x0, y0, cz - span / 2]), 3));
    world.add(new THREE.Line(g, edgeMaterial));
  };
  terraces.forEach((t, i) => {
    // the level's top
    const top = new THREE.Mesh(new THREE.PlaneGeometry(t.x_to_m - t.x_from_m, span), terraceMaterial);
    top.rotation.x = -Math.PI / 2;
    top.position.set((t.x_from_m + t.x_to_m) / 2, t.y_m - 0.0005, cz);
    world.add(top);
    edgeLine(t.x_from_m, t.y_m, t.x_to_m, t.y_m);
    // the riser up or down to the next level
    const next = terraces[i + 1];
    if (next && next.y_m !== t.y_m) {
      const riser = new THREE.Mesh(new THREE.PlaneGeometry(span, Math.abs(next.y_m - t.y_m)), terraceMaterial);
      riser.rotation.y = Math.PI / 2;
      riser.position.set(t.x_to_m, (t.y_m + next.y_m) / 2 - 0.0005, cz);
      world.add(riser);
    }
  });
} else {
  world.add(floor);
}
// A grid around the walker, moved in whole metres so its lines stay put on the floor.
const GRID_SIZE_M = 12;
const grid = new THREE.GridHelper(GRID_SIZE_M, Math.round(GRID_SIZE_M / data.grid_m), 0x9aa3ad, 0xc3c9d0);
grid.visible = terraces.length === 0;
world.add(grid);
const pathPositions = new Float32Array(3 * N);
for (let i = 0; i < N; i++) {
  const level = levelOfStep.get(stepNumber[i]) || 0;
  pathPositions.set([origin[3 * i], level + 0.001, origin[3 * i + 2]], 3 * i);
}
const pathGeometry = new THREE.BufferGeometry();
pathGeometry.setAttribute("position", new THREE.BufferAttribute(pathPositions, 3));
world.add(new THREE.Line(pathGeometry, new THREE.LineBasicMaterial({ color: 0x2a9d4a })));

// The walker's parts.
const colours = { stance: 0x1f5fa8, swing: 0xe07b1a, body: 0x5a5f66 };
const material = {};
for (const [role, c] of Object.entries(colours)) {
  material[role] = new THREE.MeshStandardMaterial({ color: c, roughness: 0.5, metalness: 0.1 });
}
const yAxis = new THREE.Vector3(0, 1, 0), zAxis = new THREE.Vector3(0, 0, 1);
const parts = data.parts.map((p) => {
  let mesh;
  if (p.kind === "rod") {
    mesh = new THREE.Mesh(new THREE.CylinderGeometry(p.radius_m, p.radius_m, 1, 16), material[p.role]);
  } else if (p.kind === "ring") {
    const tube = Math.max(0.004, p.radius_m * 0.02);
    mesh = new THREE.Mesh(new THREE.TorusGeometry(p.radius_m, tube, 10, 96), material[p.role]);
  } else {
    const r = p.mass_kg > 0 ? data.mass_sphere_m * Math.cbrt(p.mass_kg) : data.mass_sphere_m * 0.4;
    mesh = new THREE.Mesh(new THREE.SphereGeometry(r, 20, 14), material[p.role]);
  }
  world.add(mesh);
  return { p, mesh };
});

const a = new THREE.Vector3(), b = new THREE.Vector3(), d = new THREE.Vector3();
// The frames a time falls between and the weight of the later one (0: the earlier frame as
// it is). Successive frames of the same step and different times are interpolated linearly
// (so slow motion plays smoothly); frames at the same time (a heel strike's before and
// after) or of different steps never are, so impacts stay sharp. The binary puts a frame at
// every event's instant, so no interpolated pair straddles one.
const pair = { i: 0, j: 0, w: 0 };
function pairAt(t) {
  const i = frameAt(t);
  pair.i = i; pair.j = i; pair.w = 0;
  if (i + 1 < N && times[i + 1] > times[i] && stepNumber[i + 1] === stepNumber[i] && t > times[i]) {
    pair.j = i + 1;
    pair.w = Math.min((t - times[i]) / (times[i + 1] - times[i]), 1);
  }
  return pair;
}
function stored(frame, s, c) {
  return origin[3 * frame + c] + rel[3 * (frame * K + s) + c] * tr.quantum_m;
}
function point(sp, k, out) {
  const s = pointOf[k], w = sp.w;
  const at = (c) => (1 - w) * stored(sp.i, s, c) + w * stored(sp.j, s, c);
  return out.set(at(0), at(1), at(2));
}
function originAt(sp, c) {
  return (1 - sp.w) * origin[3 * sp.i + c] + sp.w * origin[3 * sp.j + c];
}

// Frame lookup: the last frame at or before t.
function frameAt(t) {
  let lo = 0, hi = N - 1;
  if (t <= times[0]) return 0;
  if (t >= times[hi]) return hi;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (times[mid] <= t) lo = mid; else hi = mid;
  }
  return lo;
}

const target = new THREE.Vector3();
const viewHeight = 0.5 * origin[1];
function pose(sp) {
  for (const { p, mesh } of parts) {
    if (p.kind === "rod") {
      point(sp, p.a, a);
      point(sp, p.b, b);
      d.subVectors(b, a);
      const len = d.length();
      mesh.position.addVectors(a, b).multiplyScalar(0.5);
      mesh.scale.set(1, Math.max(len, 1e-6), 1);
      if (len > 1e-9) mesh.quaternion.setFromUnitVectors(yAxis, d.normalize());
    } else if (p.kind === "ring") {
      point(sp, p.centre, a);
      point(sp, p.normal_tip, b);
      mesh.position.copy(a);
      mesh.quaternion.setFromUnitVectors(zAxis, d.subVectors(b, a).normalize());
    } else {
      point(sp, p.at, a);
      mesh.position.copy(a);
    }
  }
  pathGeometry.setDrawRange(0, sp.i + 1);
  const ox = originAt(sp, 0), oz = originAt(sp, 2);
  grid.position.set(Math.round(ox), 0, Math.round(oz));
  // The camera follows the hip (in world coordinates), keeping the user's view angle.
  const next = world.localToWorld(new THREE.Vector3(ox, viewHeight, oz));
  camera.position.add(d.subVectors(next, target));
  target.copy(next);
  controls.target.copy(target);
  controls.update();
}

// Controls: play/pause, speed, time slider; the overlay: time, step, events, ankle nodes.
const ui = {
  play: document.getElementById("play"),
  speed: document.getElementById("speed"),
  slider: document.getElementById("time"),
  clock: document.getElementById("clock"),
  events: document.getElementById("events"),
  nodes: document.getElementById("nodes"),
  banner: document.getElementById("banner"),
  marks: document.getElementById("marks"),
};
ui.slider.max = String(duration);
let t = 0, playing = true, last = null;
const events = data.events;
for (const e of events) {
  if (!["heel_strike", "fall", "stop", "fault", "command", "bus_off", "sensor_fault"].includes(e.kind)) continue;
  const m = document.createElement("div");
  m.className = "mark " + e.kind;
  m.style.left = (100 * Math.min(e.t_s / duration, 1)) + "%";
  m.title = e.text;
  ui.marks.appendChild(m);
}

function overlay(frame) {
  ui.clock.textContent = `t = ${t.toFixed(3)} s of ${duration.toFixed(3)} s · step ${stepNumber[frame]}`;
  const past = [];
  const nodes = {};
  // At the last frame every event has happened (a fall is located just after the last
  // recorded sample).
  const until = t >= duration ? Infinity : t + 1e-9;
  for (const e of events) {
    if (e.t_s > until) break;
    past.push(e);
    if (e.side && (e.kind === "state" || e.kind === "phase")) {
      nodes[e.side] = nodes[e.side] || { state: "", phase: "" };
      nodes[e.side][e.kind] = e.value;
    }
  }
  const shown = past.slice(-8).reverse();
  ui.events.replaceChildren(...shown.map((e, i) => {
    const li = document.createElement("li");
    li.className = e.kind + (i === 0 && t - e.t_s < 0.3 ? " fresh" : "");
    li.textContent = `${e.t_s.toFixed(3)} s  ${e.text}`;
    return li;
  }));
  if (data.firmware) {
    ui.nodes.replaceChildren(...["Left", "Right"].map((side) => {
      const n = nodes[side] || { state: "–", phase: "–" };
      const div = document.createElement("div");
      div.className = "node " + (n.phase || "").toLowerCase();
      div.textContent = `${side} ankle: ${n.state || "–"} · ${n.phase || "–"}`;
      return div;
    }));
  }
  // The emergency stop once sent, then the walk's end by failure: "fell" and the fall in
  // words for a fall, "simulation ended" and the reason for any other failure, each with its
  // time (the words from the binary).
  const end = events.find((e) => e.kind === "fall" || e.kind === "stop");
  const parts = [];
  if (data.emergency_stop_sent_s !== null && until >= data.emergency_stop_sent_s) parts.push(data.emergency_stop_text);
  if (end && until >= end.t_s) {
    const [head, reason] = end.kind === "fall" ? ["fell", end.value] : end.value.split(": ", 2);
    parts.push(`${head} at t = ${end.t_s.toFixed(3)} s: ${reason || end.value}`);
  }
  ui.banner.textContent = parts.join("; ");
}

function render() {
  const sp = pairAt(t);
  pose(sp);
  overlay(sp.i);
  ui.slider.value = String(t);
  renderer.render(scene, camera);
}

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}

function tick(now) {
  if (playing && last !== null) {
    t += ((now - last) / 1000) * Number(ui.speed.value);
    if (t >= duration) { t = duration; setPlaying(false); }
  }
  last = now;
  render();
  requestAnimationFrame(tick);
}

function setPlaying(p) {
  playing = p;
  ui.play.textContent = p ? "pause" : "play";
}
ui.play.addEventListener("click", () => {
  if (!playing && t >= duration) t = 0;
  setPlaying(!playing);
});
ui.slider.addEventListener("input", () => { t = Number(ui.slider.value); setPlaying(false); render(); });
window.addEventListener("resize", () => { resize(); render(); });

// Initial view: ahead of the walker and to its right, about 3.3 m away, looking at the
// middle of its height (the camera follows the hip over the floor, not up and down).
target.copy(world.localToWorld(new THREE.Vector3(origin[0], viewHeight, origin[2])));
camera.position.copy(target).add(new THREE.Vector3(2.0, 0.9, 2.3));
controls.target.copy(target);
resize();

api.duration_s = duration;
api.frames = N;
// Levels drawn under the steps (0 on one plane).
api.floorLevels = terraces.length;
api.frameTime = (i) => times[Math.min(Math.max(Math.trunc(Number(i)), 0), N - 1)];
api.time = () => t;
api.seek = (s) => { t = Math.min(Math.max(Number(s), 0), duration); setPlaying(false); render(); return frameAt(t); };
api.play = () => setPlaying(true);
api.pause = () => setPlaying(false);
const hash = /^#t=([0-9.]+)$/.exec(window.location.hash);
if (hash) api.seek(Number(hash[1]));
render();
api.ready = true;
requestAnimationFrame(tick);
