// adit view's page: the run in 3D (three.js) and every process's STATUS, from the server's WebSocket stream.
// window.aditState holds what the page shows, for tests and for the curious (browser console).
import * as THREE from "three";
import { OrbitControls } from "./OrbitControls.js";
import { decodeFrame, FrameType } from "./stream.js";

const state = (window.aditState = {
  connected: false, frames: 0, bytes: 0, map_points: 0, submaps: 0, sweep_points: 0,
  trajectory: { odometry: 0, corrected: 0, ground_truth: 0, keyframes: 0 }, loops: 0, status: [], info: null,
  frame_ms: 0, rendered_frames: 0,
});

// --- scene -------------------------------------------------------------------------------------------------
const container = document.getElementById("scene");
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
container.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x111111);
const camera = new THREE.PerspectiveCamera(60, 1, 0.1, 5000);
camera.up.set(0, 0, 1);
camera.position.set(-30, -30, 40);
const controls = new OrbitControls(camera, renderer.domElement);
scene.add(new THREE.AxesHelper(1));

function resize() {
  const w = container.clientWidth, h = container.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener("resize", resize);
resize();

const mapMaterial = new THREE.PointsMaterial({ size: 2, sizeAttenuation: false, vertexColors: true });
const sweepMaterial = new THREE.PointsMaterial({ size: 2, sizeAttenuation: false, vertexColors: true });
const mapGroup = new THREE.Group();
scene.add(mapGroup);
const submaps = new Map();  // id -> THREE.Points (placed by the submap's corrected pose)

function heightColour(z, out, i) {  // blue (low) .. red (high) over -2 .. +4 m
  const t = Math.min(Math.max((z + 2) / 6, 0), 1);
  const c = new THREE.Color().setHSL(0.66 * (1 - t), 1, 0.5);
  out[i] = c.r; out[i + 1] = c.g; out[i + 2] = c.b;
}

function place(object, pose) {
  object.position.set(pose.position[0], pose.position[1], pose.position[2]);
  object.quaternion.set(pose.quaternion[0], pose.quaternion[1], pose.quaternion[2], pose.quaternion[3]);
  object.updateMatrixWorld(true);
}

function addSubmap(frame) {
  const old = submaps.get(frame.id);
  if (old) { mapGroup.remove(old); old.geometry.dispose(); state.map_points -= old.userData.n; }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(frame.points, 3));
  const points = new THREE.Points(geometry, mapMaterial);
  place(points, frame.pose);
  const n = frame.points.length / 3, colours = new Float32Array(3 * n), v = new THREE.Vector3();
  for (let i = 0; i < n; ++i) {
    v.set(frame.points[3 * i], frame.points[3 * i + 1], frame.points[3 * i + 2]).applyMatrix4(points.matrixWorld);
    heightColour(v.z, colours, 3 * i);
  }
  geometry.setAttribute("color", new THREE.BufferAttribute(colours, 3));
  points.userData.n = n;
  submaps.set(frame.id, points);
  mapGroup.add(points);
  state.map_points += n;
  state.submaps = submaps.size;
}

const sweep = new THREE.Points(new THREE.BufferGeometry(), sweepMaterial);
scene.add(sweep);
let colourBy = "height";
let lastSweep = null;
function showSweep(frame) {
  lastSweep = frame;
  const n = frame.points.length / 3, colours = new Float32Array(3 * n);
  for (let i = 0; i < n; ++i) {
    if (colourBy === "intensity") {
      const t = frame.intensity[i] / 255;
      colours[3 * i] = 0.3 + 0.7 * t; colours[3 * i + 1] = 0.3 + 0.7 * t; colours[3 * i + 2] = 0.2;
    } else {
      colours[3 * i] = 1; colours[3 * i + 1] = 1; colours[3 * i + 2] = 0.6;
    }
  }
  sweep.geometry.dispose();
  sweep.geometry = new THREE.BufferGeometry();
  sweep.geometry.setAttribute("position", new THREE.BufferAttribute(frame.points, 3));
  sweep.geometry.setAttribute("color", new THREE.BufferAttribute(colours, 3));
  place(sweep, frame.pose);
  state.sweep_points = n;
}

// A line that grows (appends) or is replaced whole.
class Path {
  constructor(colour) {
    this.data = new Float32Array(3 * 1024);
    this.n = 0;
    // Drawn over the map (depth test off): a trajectory runs inside the roadway, under its roof.
    this.line = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: colour, depthTest: false }));
    this.line.frustumCulled = false;
    this.line.renderOrder = 1;
    scene.add(this.line);
    this.upload();
  }
  update(positions, replace) {
    if (replace) this.n = 0;
    const need = 3 * this.n + positions.length;
    if (need > this.data.length) {
      const bigger = new Float32Array(Math.max(need, 2 * this.data.length));
      bigger.set(this.data.subarray(0, 3 * this.n));
      this.data = bigger;
    }
    this.data.set(positions, 3 * this.n);
    this.n += positions.length / 3;
    this.upload();
  }
  upload() {
    this.line.geometry.dispose();
    this.line.geometry = new THREE.BufferGeometry();
    this.line.geometry.setAttribute("position", new THREE.BufferAttribute(this.data, 3));
    this.line.geometry.setDrawRange(0, this.n);
  }
}
const paths = [new Path(0x888888), new Path(0x40e040), new Path(0x4090ff)];  // odometry, corrected, truth
const kinds = ["odometry", "corrected", "ground_truth", "keyframes"];
// Keyframes (corrected): white dots over the map.
const keyframes = new THREE.Points(new THREE.BufferGeometry(),
  new THREE.PointsMaterial({ color: 0xffffff, size: 5, sizeAttenuation: false, depthTest: false }));
keyframes.frustumCulled = false;
keyframes.renderOrder = 3;
scene.add(keyframes);
function showKeyframes(positions) {
  keyframes.geometry.dispose();
  keyframes.geometry = new THREE.BufferGeometry();
  keyframes.geometry.setAttribute("position", new THREE.BufferAttribute(positions, 3));
  state.trajectory.keyframes = positions.length / 3;
}

const loops = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xff40d0, depthTest: false }));
loops.frustumCulled = false;
loops.renderOrder = 2;
scene.add(loops);
const robot = new THREE.AxesHelper(2);
scene.add(robot);
let robotPose = null;

function reset() {
  for (const p of submaps.values()) { mapGroup.remove(p); p.geometry.dispose(); }
  submaps.clear();
  state.map_points = 0; state.submaps = 0; state.loops = 0;
  for (const p of paths) p.update(new Float32Array(0), true);
  showKeyframes(new Float32Array(0));
  for (const k of kinds) state.trajectory[k] = 0;
  loops.geometry = new THREE.BufferGeometry();
}

// Measurement only (?stress_points=N): N extra points along a 600 m synthetic roadway, in 0.5 m voxels' worth
// of 10,000-point submaps, to measure the frame time with a large map (README, "Watching a run").
const stress = Number(new URLSearchParams(location.search).get("stress_points") || 0);
for (let done = 0, id = 1000000; done < stress; ++id) {
  const n = Math.min(10000, stress - done), points = new Float32Array(3 * n);
  for (let i = 0; i < n; ++i) {
    const a = Math.random() * 2 * Math.PI, x = Math.random() * 600 - 300;
    points.set([x, 2.5 * Math.cos(a), 1.5 + 2 * Math.sin(a)], 3 * i);
  }
  addSubmap({ id, version: 0, pose: { position: [0, 0, 0], quaternion: [0, 0, 0, 1] }, points });
  done += n;
}

// --- panel --------------------------------------------------------------------------------------------------
const $ = (id) => document.getElementById(id);
let bandwidth = { bytes: 0, since: performance.now(), rate: 0 };

function fact(name, value) { return `<div><span>${name}</span><span>${value}</span></div>`; }
function escape(s) { return String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]); }

function showInfo(info) {
  state.info = info;
  state.status = info.status;
  const s = info.server;
  $("facts").innerHTML =
    fact("distance", `${info.distance_m.toFixed(1)} m`) + fact("loops", info.loops) +
    fact("map points", `${state.map_points.toLocaleString()} (${state.submaps} submaps)`) +
    fact("sweep points shown", state.sweep_points) + fact("stream", `${(bandwidth.rate / 1e3).toFixed(1)} kB/s`) +
    fact("frames dropped / malformed", `${s.frames_dropped} / ${s.malformed}`) +
    fact("frame time", `${state.frame_ms.toFixed(1)} ms`);
  const rows = info.status.map((r) => {
    const counters = Object.entries(r.counters).filter(([, v]) => v !== 0).map(([k, v]) => `${k} ${v}`).join(", ");
    const error = r.last_error ? ` | ${r.last_error}` : "";
    return `<tr class="${r.state === "behind" ? "behind" : ""}"><td>${escape(r.process)}</td><td>${escape(r.state)}</td>` +
      `<td>${r.rate_hz.toFixed(1)}</td><td>${r.p95_ms.toFixed(1)}</td><td>${Math.round(100 * r.busy)}%</td></tr>` +
      (counters || error ? `<tr><td colspan="5" class="counters">${escape(counters + error)}</td></tr>` : "");
  });
  $("status").tBodies[0].innerHTML = rows.join("");
  $("commands").hidden = !info.commands_allowed;  // adit view --allow-commands, live runs only
  if (info.log) {
    $("playback").hidden = false;
    const slider = $("slider");
    slider.max = info.log.duration_s;
    if (!slider.matches(":active")) slider.value = info.log.position_s;
    $("time").textContent = `${info.log.position_s.toFixed(1)} / ${info.log.duration_s.toFixed(1)} s`;
    $("play").textContent = info.log.playing ? "pause" : "play";
    showSpeed(info.log.speed);
  }
}

// The speed menu shows the server's speed (adit view --speed 20, or another page's choice), with an entry
// added for a speed the menu lacks; left alone while the operator has the menu open.
function showSpeed(speed) {
  const menu = $("speed"), value = String(speed);
  if (document.activeElement === menu || menu.value === value) return;
  if (![...menu.options].some((o) => o.value === value)) {
    const option = new Option(value);
    const after = [...menu.options].find((o) => Number(o.value) > speed);
    menu.add(option, after || null);
  }
  menu.value = value;
}

// --- stream -------------------------------------------------------------------------------------------------
let socket = null;
function connect() {
  socket = new WebSocket(`ws://${location.host}/ws`);
  socket.binaryType = "arraybuffer";
  socket.onopen = () => { state.connected = true; $("connection").textContent = "connected"; };
  socket.onclose = () => {
    state.connected = false;
    $("connection").textContent = "disconnected, retrying...";
    setTimeout(connect, 2000);
  };
  socket.onmessage = (event) => {
    state.frames += 1;
    state.bytes += event.data.byteLength;
    bandwidth.bytes += event.data.byteLength;
    const frame = decodeFrame(event.data);
    if (!frame) return;
    switch (frame.type) {
      case FrameType.Submap: addSubmap(frame); break;
      case FrameType.SubmapPose: { const p = submaps.get(frame.id); if (p) place(p, frame.pose); break; }
      case FrameType.Sweep: showSweep(frame); break;
      case FrameType.Trajectory:
        if (frame.kind === 3) { showKeyframes(frame.positions); break; }
        paths[frame.kind].update(frame.positions, frame.replace);
        state.trajectory[kinds[frame.kind]] = paths[frame.kind].n;
        break;
      case FrameType.Loops:
        loops.geometry.dispose();
        loops.geometry = new THREE.BufferGeometry();
        loops.geometry.setAttribute("position", new THREE.BufferAttribute(frame.segments, 3));
        state.loops = frame.segments.length / 6;
        break;
      case FrameType.Robot: robotPose = frame.pose; place(robot, frame.pose); break;
      case FrameType.Info: showInfo(frame.info); break;
      case FrameType.Reset: reset(); break;
    }
  };
}
connect();
const send = (text) => socket && socket.readyState === 1 && socket.send(text);
$("slider").addEventListener("change", (e) => send(`seek ${e.target.value}`));
$("play").addEventListener("click", () => send($("play").textContent === "pause" ? "pause" : "play"));
$("speed").addEventListener("change", (e) => send(`speed ${e.target.value}`));
$("save-map").addEventListener("click", () => send(`save_map ${$("map-name").value.trim()}`.trim()));
$("colour").addEventListener("change", (e) => { colourBy = e.target.value; if (lastSweep) showSweep(lastSweep); });

// --- views and rendering ------------------------------------------------------------------------------------
let viewMode = "orbit";
for (const mode of ["orbit", "top", "follow"]) {
  $(`view-${mode}`).addEventListener("click", () => {
    viewMode = mode;
    for (const m of ["orbit", "top", "follow"]) $(`view-${m}`).classList.toggle("on", m === mode);
    controls.enabled = mode === "orbit";
  });
}

function followCamera() {
  if (!robotPose) return;
  const p = new THREE.Vector3(...robotPose.position);
  if (viewMode === "top") {  // the whole trajectory from above
    const path = paths[1].n ? paths[1] : paths[0];
    const box = new THREE.Box3().setFromArray(path.data.subarray(0, 3 * path.n)).expandByPoint(p);
    const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3());
    const extent = Math.max(size.x / camera.aspect, size.y, 20) + 50;  // the map reaches past the path
    camera.position.set(centre.x, centre.y - 0.01, centre.z + extent / (2 * Math.tan((camera.fov * Math.PI) / 360)));
    camera.lookAt(centre);
  } else if (viewMode === "follow") {
    const q = new THREE.Quaternion(...robotPose.quaternion);
    const behind = new THREE.Vector3(-12, 0, 6).applyQuaternion(q);
    camera.position.copy(p).add(behind);
    camera.lookAt(p);
  }
}

let last = performance.now();
function render(now) {
  const dt = now - last;
  last = now;
  state.frame_ms = state.rendered_frames ? 0.9 * state.frame_ms + 0.1 * dt : dt;
  state.rendered_frames += 1;
  if (now - bandwidth.since > 2000) {
    bandwidth.rate = (bandwidth.bytes * 1000) / (now - bandwidth.since);
    bandwidth = { bytes: 0, since: now, rate: bandwidth.rate };
  }
  state.stream_bytes_per_s = bandwidth.rate;
  followCamera();
  if (viewMode === "orbit") controls.update();
  renderer.render(scene, camera);
  requestAnimationFrame(render);
}
requestAnimationFrame(render);
