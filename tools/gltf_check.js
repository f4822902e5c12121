// A small glTF 2.0 reader for a browser, with no library: enough to do what a viewer does with
// our files (parse GLB or .gltf, read accessors, play the first animation, pose the skin, skin
// the mesh on the CPU) and report the result, so a headless browser can check a file the way
// a web viewer will see it. Driven by tools/chromium_gltf_check.py, which supplies GLTF_B64
// (the file) and TIMES (seconds) and reads back the JSON this writes into <pre id="result">.
"use strict";

const COMPONENTS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };
const READERS = {
  5120: [1, (d, o) => d.getInt8(o)], 5121: [1, (d, o) => d.getUint8(o)],
  5122: [2, (d, o) => d.getInt16(o, true)], 5123: [2, (d, o) => d.getUint16(o, true)],
  5125: [4, (d, o) => d.getUint32(o, true)], 5126: [4, (d, o) => d.getFloat32(o, true)],
};

function fromBase64(text) {
  const raw = atob(text);
  const bytes = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
  return bytes;
}

// The JSON document and its buffers, from GLB bytes or from .gltf text with data: URIs.
function parseFile(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (bytes.length >= 12 && view.getUint32(0, true) === 0x46546c67) {
    if (view.getUint32(4, true) !== 2) throw new Error("GLB version " + view.getUint32(4, true) + ", expected 2");
    if (view.getUint32(8, true) !== bytes.length) throw new Error("GLB length field disagrees with the file size");
    let json = null, bin = null;
    for (let at = 12; at < bytes.length;) {
      const length = view.getUint32(at, true), type = view.getUint32(at + 4, true);
      if (at + 8 + length > bytes.length) throw new Error("GLB chunk at " + at + " runs past the end");
      const chunk = bytes.subarray(at + 8, at + 8 + length);
      if (type === 0x4e4f534a) json = JSON.parse(new TextDecoder().decode(chunk));
      else if (type === 0x004e4942) bin = chunk;
      at += 8 + length;
    }
    if (!json) throw new Error("GLB has no JSON chunk");
    const buffers = (json.buffers || []).map((b, i) => (b.uri === undefined ? bin : dataUri(b.uri, i)));
    return { json, buffers };
  }
  const json = JSON.parse(new TextDecoder().decode(bytes));
  return { json, buffers: (json.buffers || []).map((b, i) => dataUri(b.uri, i)) };
}

function dataUri(uri, i) {
  const m = /^data:[^,]*;base64,(.*)$/.exec(uri || "");
  if (!m) throw new Error("buffer " + i + " is not embedded (uri " + String(uri).slice(0, 40) + ")");
  return fromBase64(m[1]);
}

// An accessor's elements as arrays of numbers (normalised integers scaled as the spec says).
function readAccessor(file, index) {
  const a = file.json.accessors[index];
  if (a.sparse) throw new Error("accessor " + index + ": sparse accessors are not read here");
  const [size, read] = READERS[a.componentType];
  const n = COMPONENTS[a.type];
  const view = file.json.bufferViews[a.bufferView];
  const buffer = file.buffers[view.buffer];
  const stride = view.byteStride || size * n;
  const start = (view.byteOffset || 0) + (a.byteOffset || 0);
  if (start + stride * (a.count - 1) + size * n > (view.byteOffset || 0) + view.byteLength) throw new Error("accessor " + index + " runs past its buffer view");
  const data = new DataView(buffer.buffer, buffer.byteOffset, buffer.byteLength);
  const scale = a.normalized ? { 5120: 127, 5121: 255, 5122: 32767, 5123: 65535 }[a.componentType] : 1;
  const out = [];
  for (let i = 0; i < a.count; i++) {
    const e = [];
    for (let c = 0; c < n; c++) e.push(read(data, start + i * stride + c * size) / scale);
    out.push(e);
  }
  return out;
}

// 4x4 matrices as 16 numbers, column-major, as glTF stores them.
function multiply(a, b) {
  const o = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) o[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return o;
}

function compose(t, q, s) {
  const [x, y, z, w] = q;
  const m = [
    1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0,
    2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0,
    2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0,
    t[0], t[1], t[2], 1,
  ];
  for (let c = 0; c < 3; c++) for (let r = 0; r < 3; r++) m[c * 4 + r] *= s[c];
  return m;
}

function apply(m, p) {
  return [0, 1, 2].map((r) => m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
}

function slerp(a, b, u) {
  let d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  if (d < 0) { b = b.map((v) => -v); d = -d; }
  let ka = 1 - u, kb = u;
  if (d < 0.9995) {
    const th = Math.acos(d), s = Math.sin(th);
    ka = Math.sin((1 - u) * th) / s; kb = Math.sin(u * th) / s;
  }
  const q = a.map((v, i) => ka * v + kb * b[i]);
  const len = Math.hypot(...q);
  return q.map((v) => v / len);
}

// A sampler's value at time t: clamped outside its keys; LINEAR, STEP and CUBICSPLINE.
function sample(times, values, mode, path, t) {
  const last = times.length - 1;
  const cubic = mode === "CUBICSPLINE";
  const value = (i) => (cubic ? values[3 * i + 1] : values[i]);
  if (t <= times[0]) return value(0);
  if (t >= times[last]) return value(last);
  let i = 0;
  while (times[i + 1] <= t) i++;
  const dt = times[i + 1] - times[i];
  const u = (t - times[i]) / dt;
  if (mode === "STEP") return value(i);
  if (cubic) {
    const u2 = u * u, u3 = u2 * u;
    const p0 = values[3 * i + 1], m0 = values[3 * i + 2], p1 = values[3 * (i + 1) + 1], m1 = values[3 * (i + 1)];
    const v = p0.map((_, c) => (2 * u3 - 3 * u2 + 1) * p0[c] + (u3 - 2 * u2 + u) * dt * m0[c] + (-2 * u3 + 3 * u2) * p1[c] + (u3 - u2) * dt * m1[c]);
    if (path !== "rotation") return v;
    const len = Math.hypot(...v);
    return v.map((x) => x / len);
  }
  if (path === "rotation") return slerp(values[i], values[i + 1], u);
  return values[i].map((v, c) => v + (values[i + 1][c] - v) * u);
}

// Every node's world matrix at time t under the first animation.
function pose(file, animation, t) {
  const nodes = file.json.nodes;
  const trs = nodes.map((n) => ({ t: n.translation || [0, 0, 0], r: n.rotation || [0, 0, 0, 1], s: n.scale || [1, 1, 1], m: n.matrix }));
  for (const ch of animation ? animation.channels : []) {
    const path = ch.target.path;
    if (!["translation", "rotation", "scale"].includes(path) || ch.target.node === undefined) continue;
    const v = sample(ch.times, ch.values, ch.mode, path, t);
    trs[ch.target.node][{ translation: "t", rotation: "r", scale: "s" }[path]] = v;
    trs[ch.target.node].m = undefined;
  }
  const world = new Array(nodes.length).fill(null);
  const visit = (i, parent) => {
    const n = trs[i];
    const local = n.m || compose(n.t, n.r, n.s);
    world[i] = parent ? multiply(parent, local) : local;
    for (const c of nodes[i].children || []) visit(c, world[i]);
  };
  const scene = file.json.scenes ? file.json.scenes[file.json.scene || 0] : { nodes: [...nodes.keys()] };
  for (const root of scene.nodes) visit(root, null);
  return world;
}

// The first animation with every channel's keys read once.
function loadAnimation(file) {
  const a = (file.json.animations || [])[0];
  if (!a) return null;
  const channels = a.channels.map((ch) => {
    const s = a.samplers[ch.sampler];
    return { target: ch.target, times: readAccessor(file, s.input).map((e) => e[0]), values: readAccessor(file, s.output), mode: s.interpolation || "LINEAR" };
  });
  for (const ch of channels) {
    for (let i = 1; i < ch.times.length; i++) if (!(ch.times[i] > ch.times[i - 1])) throw new Error("animation key times do not increase at key " + i);
  }
  return { name: a.name, channels, end: Math.max(0, ...channels.map((c) => c.times[c.times.length - 1])) };
}

// The skinned mesh's vertices at one pose: joint matrix = world(joint) * inverseBind(joint).
function skinMesh(file, world) {
  const meshNode = file.json.nodes.findIndex((n) => n.mesh !== undefined && n.skin !== undefined);
  if (meshNode < 0) return null;
  const skin = file.json.skins[file.json.nodes[meshNode].skin];
  const ibm = skin.inverseBindMatrices !== undefined ? readAccessor(file, skin.inverseBindMatrices) : skin.joints.map(() => compose([0, 0, 0], [0, 0, 0, 1], [1, 1, 1]));
  const jointMatrix = skin.joints.map((node, k) => multiply(world[node], ibm[k]));
  const triangles = [], vertices = [];
  for (const prim of file.json.meshes[file.json.nodes[meshNode].mesh].primitives) {
    const pos = readAccessor(file, prim.attributes.POSITION);
    const joints = readAccessor(file, prim.attributes.JOINTS_0);
    const weights = readAccessor(file, prim.attributes.WEIGHTS_0);
    const base = vertices.length;
    pos.forEach((p, v) => {
      const out = [0, 0, 0];
      for (let k = 0; k < 4; k++) {
        if (weights[v][k] === 0) continue;
        const q = apply(jointMatrix[joints[v][k]], p);
        for (let c = 0; c < 3; c++) out[c] += weights[v][k] * q[c];
      }
      vertices.push({ p: out, joint: skin.joints[joints[v][0]] });
    });
    const idx = prim.indices !== undefined ? readAccessor(file, prim.indices).map((e) => e[0]) : pos.map((_, i) => i);
    for (let i = 0; i + 2 < idx.length; i += 3) triangles.push([base + idx[i], base + idx[i + 1], base + idx[i + 2]]);
  }
  return { vertices, triangles };
}

// How far the skinned body strays from the bones it should wrap: for each vertex, the distance
// to the nearest bone that touches its joint (leaving it for a child node, or arriving from its
// parent node), over the longest of those bones (a near-zero bone must not blow the ratio up;
// a joint whose bones are all below a millionth of the body's size, as LAFAN1's *End joints
// are, has nothing to wrap and is skipped).
function meshOffBone(file, world, mesh) {
  const at = (i) => [world[i][12], world[i][13], world[i][14]];
  const parent = new Array(file.json.nodes.length).fill(-1);
  file.json.nodes.forEach((n, i) => (n.children || []).forEach((c) => (parent[c] = i)));
  const lo = [0, 1, 2].map((c) => Math.min(...world.filter(Boolean).map((m) => m[12 + c])));
  const hi = [0, 1, 2].map((c) => Math.max(...world.filter(Boolean).map((m) => m[12 + c])));
  const size = Math.hypot(...hi.map((x, c) => x - lo[c]));
  let worst = 0;
  for (const v of mesh.vertices) {
    const bones = (file.json.nodes[v.joint].children || []).map((c) => [v.joint, c]);
    if (parent[v.joint] >= 0) bones.push([parent[v.joint], v.joint]);
    let nearest = Infinity, longest = 0;
    for (const [from, to] of bones) {
      const a = at(from), b = at(to);
      const ab = b.map((x, i) => x - a[i]);
      const len2 = ab.reduce((s, x) => s + x * x, 0);
      longest = Math.max(longest, Math.sqrt(len2));
      const u = len2 > 0 ? Math.max(0, Math.min(1, ab.reduce((s, x, i) => s + x * (v.p[i] - a[i]), 0) / len2)) : 0;
      nearest = Math.min(nearest, Math.hypot(...v.p.map((x, i) => x - (a[i] + u * ab[i]))));
    }
    if (longest > 1e-6 * size) worst = Math.max(worst, nearest / longest);
  }
  return worst;
}

// A side view of the skinned body (flat-shaded triangles, far ones first) on the page's canvas.
function draw(mesh, label) {
  const canvas = document.getElementById("view");
  const g = canvas.getContext("2d");
  g.fillStyle = "#f4f4f0"; g.fillRect(0, 0, canvas.width, canvas.height);
  if (!mesh) return;
  const yaw = -0.6, cy = Math.cos(yaw), sy = Math.sin(yaw);
  const view = mesh.vertices.map(({ p }) => [p[0] * cy + p[2] * sy, p[1], -p[0] * sy + p[2] * cy]);
  const lo = [0, 1].map((c) => Math.min(...view.map((v) => v[c]))), hi = [0, 1].map((c) => Math.max(...view.map((v) => v[c])));
  const scale = 0.85 * Math.min(canvas.width / (hi[0] - lo[0] || 1), canvas.height / (hi[1] - lo[1] || 1));
  const px = (v) => [canvas.width / 2 + (v[0] - (lo[0] + hi[0]) / 2) * scale, canvas.height / 2 - (v[1] - (lo[1] + hi[1]) / 2) * scale];
  const order = mesh.triangles.map((t) => [t, (view[t[0]][2] + view[t[1]][2] + view[t[2]][2]) / 3]).sort((a, b) => a[1] - b[1]);
  for (const [t] of order) {
    const [a, b, c] = t.map((i) => view[i]);
    const u = b.map((x, i) => x - a[i]), w = c.map((x, i) => x - a[i]);
    const n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
    const shade = Math.round(90 + 130 * Math.abs(n[2]) / (Math.hypot(...n) || 1));
    g.fillStyle = "rgb(" + shade + "," + Math.round(shade * 0.8) + "," + Math.round(shade * 0.55) + ")";
    g.beginPath();
    t.map((i) => px(view[i])).forEach(([x, y], k) => (k ? g.lineTo(x, y) : g.moveTo(x, y)));
    g.closePath(); g.fill();
  }
  g.fillStyle = "#333"; g.font = "14px sans-serif"; g.fillText(label, 10, 20);
}

function run() {
  const out = { ok: false };
  try {
    const file = parseFile(fromBase64(GLTF_B64));
    const animation = loadAnimation(file);
    const skin = (file.json.skins || [])[0];
    if (!skin) throw new Error("no skin");
    out.joints = skin.joints.map((n) => file.json.nodes[n].name || "node" + n);
    out.animation = animation ? { name: animation.name || null, channels: animation.channels.length, end: animation.end } : null;
    out.positions = [];
    out.mesh_off_bone = 0;
    const middle = Math.floor(TIMES.length / 2);
    let shown = null;
    for (const [k, t] of TIMES.entries()) {
      const world = pose(file, animation, t);
      out.positions.push(skin.joints.map((n) => [world[n][12], world[n][13], world[n][14]]));
      const mesh = skinMesh(file, world);
      if (mesh) {
        out.mesh_off_bone = Math.max(out.mesh_off_bone, meshOffBone(file, world, mesh));
        out.mesh_vertices = mesh.vertices.length;
        out.mesh_triangles = mesh.triangles.length;
      }
      if (k === middle) shown = mesh;
    }
    draw(shown, LABEL + "  t = " + (TIMES[middle] || 0).toFixed(3) + " s");
    out.ok = true;
  } catch (e) {
    out.error = String(e && e.message ? e.message : e);
  }
  document.getElementById("result").textContent = JSON.stringify(out);
}

run();
