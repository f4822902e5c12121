// menagerie motion viewer: plays tracks in 3D on a 2D canvas with our own perspective projection.
// Data: #meta (JSON: tracks, legend, options) and #data (base64 of one zlib stream holding each
// track's quantised positions as zigzagged prediction residuals; see lib/render/html.rs).
'use strict';
(function () {
  const meta = JSON.parse(document.getElementById('meta').textContent);
  const $ = (id) => document.getElementById(id);
  const canvas = $('view'), ctx = canvas.getContext('2d');
  const FOV = 40 * Math.PI / 180;
  const BACKGROUND = '#fafafa', GRID = '#dadada', SHADOW = '#c4c4c4', BONE = '#333333';

  // ---- data ----------------------------------------------------------------------------------

  async function inflate(text) {
    const binary = atob(text.trim());
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    if (typeof DecompressionStream === 'undefined') {
      throw new Error('this browser cannot decompress the motion (no DecompressionStream): use a current Chrome, Firefox or Safari');
    }
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // Undo html.rs's encoding: series per point and axis, stored relative to a reference point
  // (the parent, decoded earlier), as zigzagged residuals of a prediction from the previous
  // frame(s), low bytes then high bytes; 16-bit levels then scale back to positions.
  function decodeTrack(t, bytes) {
    const F = t.frames, P = t.points, n = F * P * 3;
    const lo = bytes.subarray(t.offset, t.offset + n), hi = bytes.subarray(t.offset + n, t.offset + 2 * n);
    const levels = new Uint16Array(n);
    const pos = new Float32Array(n);
    let k = 0;
    for (let p = 0; p < P; p++) {
      const ref = t.reference[p];
      for (let a = 0; a < 3; a++) {
        const base = ref === null ? -1 : (ref * 3 + a) * F;
        let prev = 0, prev2 = 0;
        for (let f = 0; f < F; f++, k++) {
          const z = lo[k] | (hi[k] << 8);
          const e = (z >>> 1) ^ -(z & 1);
          const pred = f === 0 ? 0 : (t.order === 2 && f >= 2 ? 2 * prev - prev2 : prev);
          const v = (pred + e) & 0xffff;
          prev2 = prev; prev = v;
          const q = base < 0 ? v : (v + levels[base + f]) & 0xffff;
          levels[k] = q;
          pos[(f * P + p) * 3 + a] = t.min[a] + q * t.step[a];
        }
      }
    }
    t.pos = pos;
    // The largest gap between our decoding and html.rs's probes (the self test reports it).
    t.probeError = 0;
    for (const [f, p, want] of t.probes) {
      for (let a = 0; a < 3; a++) t.probeError = Math.max(t.probeError, Math.abs(pos[(f * P + p) * 3 + a] - want[a]));
    }
  }

  // Bounds, ground and body size of a set of tracks (one view), and the box around the first
  // track's root that following keeps in view (sideways relative to the root, heights absolute).
  function measure(tracks) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    const rlo = [Infinity, Infinity, Infinity], rhi = [-Infinity, -Infinity, -Infinity];
    let body = 0;
    tracks.forEach((t, k) => {
      for (let i = 0; i < t.pos.length; i += 3) {
        for (let a = 0; a < 3; a++) {
          const v = t.pos[i + a];
          if (v < lo[a]) lo[a] = v;
          if (v > hi[a]) hi[a] = v;
        }
      }
      // Body size: the largest single-frame extent, sampled (a long walk is not a big body).
      const every = Math.max(1, Math.floor(t.frames / 200));
      for (let f = 0; f < t.frames; f += every) {
        const l = [Infinity, Infinity, Infinity], h = [-Infinity, -Infinity, -Infinity];
        const r = root(tracks[0], Math.min(f, tracks[0].frames - 1));
        for (let p = 0; p < t.points; p++) {
          for (let a = 0; a < 3; a++) {
            const v = t.pos[(f * t.points + p) * 3 + a];
            if (v < l[a]) l[a] = v;
            if (v > h[a]) h[a] = v;
            const rel = a === 1 ? v : v - r[a];
            if (rel < rlo[a]) rlo[a] = rel;
            if (rel > rhi[a]) rhi[a] = rel;
          }
        }
        body = Math.max(body, Math.hypot(h[0] - l[0], h[1] - l[1], h[2] - l[2]));
      }
    });
    const size = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    body = body > 0 ? body : (size > 0 ? size : 1);
    return { lo, hi, rlo, rhi, body, ground: lo[1] };
  }

  function root(t, f) {
    const i = f * t.points * 3;
    return [t.pos[i], t.pos[i + 1], t.pos[i + 2]];
  }

  // ---- state ---------------------------------------------------------------------------------

  const tracks = meta.tracks;
  const views = [];
  const maxFps = Math.max(...tracks.map((t) => t.fps));
  const duration = Math.max(...tracks.map((t) => t.frames / t.fps));
  const steps = Math.max(1, Math.round(duration * maxFps));
  const DEFAULT_PITCH = 0.3;
  const cam = { yaw: 0.5, pitch: DEFAULT_PITCH, zoom: 1, panX: 0, panY: 0 };
  let defaultYaw = 0.5;
  let time = 0, playing = meta.autoplay, speed = meta.speed, follow = meta.follow, dirty = true;
  let hovered = null, projected = [];

  // The frame a track shows at a time (tracks shorter than the longest hold their last frame).
  function frameOf(t, at) {
    return Math.max(0, Math.min(t.frames - 1, Math.floor(at * t.fps + 1e-6)));
  }

  function labelColour(index) {
    return index === null || index === undefined || !meta.legend[index] ? null : meta.legend[index].colour;
  }

  // ---- camera and projection -----------------------------------------------------------------

  function orientation(yaw, pitch) {
    const cp = Math.cos(pitch), sp = Math.sin(pitch), cy = Math.cos(yaw), sy = Math.sin(yaw);
    return {
      back: [cp * sy, sp, cp * cy],                 // from the target towards the eye
      right: [cy, 0, -sy],
      up: [-sp * sy, cp, -sp * cy],                 // back x right
    };
  }

  const dot = (u, v) => u[0] * v[0] + u[1] * v[1] + u[2] * v[2];

  // The distance at which a box fills the view from the default direction: every corner inside
  // the frustum. Fitted once per view shape, not per orbit, so orbiting never zooms.
  function fitDistance(lo, hi, aspect, body) {
    const o = orientation(defaultYaw, DEFAULT_PITCH);
    const tanY = Math.tan(FOV / 2), tanX = tanY * aspect;
    // A flat or still creature still gets some room (and the camera a distance above zero).
    const half = [0, 1, 2].map((a) => Math.max((hi[a] - lo[a]) / 2, body * 0.05));
    let d = 0;
    for (let c = 0; c < 8; c++) {
      const v = half.map((h, a) => (c >> a) & 1 ? h : -h);
      const z = dot(v, o.back);
      d = Math.max(d, z + Math.abs(dot(v, o.right)) / tanX, z + Math.abs(dot(v, o.up)) / tanY);
    }
    return d * 1.08;
  }

  // A camera for one view rectangle: orbit about the view's target at a distance that fits the
  // view's whole path (or, following, the box around its root), whatever the creature's size.
  function camera(view, rect) {
    const m = view.m;
    let lo = m.lo, hi = m.hi;
    if (follow) {
      const r = root(view.tracks[0], frameOf(view.tracks[0], time));
      lo = [r[0] + m.rlo[0], m.rlo[1], r[2] + m.rlo[2]];
      hi = [r[0] + m.rhi[0], m.rhi[1], r[2] + m.rhi[2]];
    }
    const target = lo.map((v, a) => (v + hi[a]) / 2);
    const aspect = rect.w / rect.h;
    const fit = fitDistance(lo, hi, aspect, m.body), dist = fit / cam.zoom;
    const { back, right, up } = orientation(cam.yaw, cam.pitch);
    // Pan moves the target in the screen plane, in units of the fitted view's half height.
    const unit = fit * Math.tan(FOV / 2);
    for (let a = 0; a < 3; a++) target[a] += (cam.panX * right[a] + cam.panY * up[a]) * unit;
    const eye = target.map((v, a) => v + back[a] * dist);
    const focal = (rect.h / 2) / Math.tan(FOV / 2);
    const near = dist * 0.02;
    return {
      project(x, y, z) {
        const d = [x - eye[0], y - eye[1], z - eye[2]];
        const depth = -dot(d, back);
        if (depth < near) return null;
        return [rect.x + rect.w / 2 + (dot(d, right) * focal) / depth, rect.y + rect.h / 2 - (dot(d, up) * focal) / depth, depth];
      },
    };
  }

  // A round grid step (1, 2 or 5 times a power of ten) near a quarter of the body size.
  function gridStep(body) {
    const raw = body / 4, p = Math.pow(10, Math.floor(Math.log10(raw)));
    const m = raw / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
  }

  // ---- drawing -------------------------------------------------------------------------------

  // Adds a segment between two projected points to the current path (skipped when either end
  // is behind the camera); `stroke` draws a batch of them at once, which keeps frames cheap.
  function segment(a, b) {
    if (!a || !b) return;
    ctx.moveTo(a[0], a[1]);
    ctx.lineTo(b[0], b[1]);
  }

  function stroke(style, width, add) {
    ctx.beginPath();
    add();
    ctx.strokeStyle = style;
    ctx.lineWidth = width;
    ctx.stroke();
  }

  function drawGrid(view, c) {
    const m = view.m;
    let step = gridStep(m.body);
    const margin = m.body;
    let x0 = m.lo[0] - margin, x1 = m.hi[0] + margin, z0 = m.lo[2] - margin, z1 = m.hi[2] + margin;
    // Long paths: coarser lines rather than thousands of them.
    while ((x1 - x0) / step + (z1 - z0) / step > 400) step *= 2;
    x0 = Math.floor(x0 / step) * step; x1 = Math.ceil(x1 / step) * step;
    z0 = Math.floor(z0 / step) * step; z1 = Math.ceil(z1 / step) * step;
    const y = m.ground;
    // Lines are cut into pieces so perspective clipping at the near plane only drops short bits.
    const pieces = 8;
    stroke(GRID, 1, () => {
      for (let x = x0; x <= x1 + step / 2; x += step) {
        for (let i = 0; i < pieces; i++) {
          segment(c.project(x, y, z0 + ((z1 - z0) * i) / pieces), c.project(x, y, z0 + ((z1 - z0) * (i + 1)) / pieces));
        }
      }
      for (let z = z0; z <= z1 + step / 2; z += step) {
        for (let i = 0; i < pieces; i++) {
          segment(c.project(x0 + ((x1 - x0) * i) / pieces, y, z), c.project(x0 + ((x1 - x0) * (i + 1)) / pieces, y, z));
        }
      }
    });
  }

  function drawTrack(view, c, t, k) {
    const f = frameOf(t, time);
    const pts = [];
    for (let p = 0; p < t.points; p++) {
      const i = (f * t.points + p) * 3;
      pts.push(c.project(t.pos[i], t.pos[i + 1], t.pos[i + 2]));
    }
    // Shadows on the ground show height and depth that one projection hides.
    stroke(SHADOW, 2, () => {
      for (let p = 0; p < t.points; p++) {
        const q = t.parents[p];
        if (q === null) continue;
        const i = (f * t.points + p) * 3, j = (f * t.points + q) * 3;
        segment(c.project(t.pos[j], view.m.ground, t.pos[j + 2]), c.project(t.pos[i], view.m.ground, t.pos[i + 2]));
      }
    });
    const plain = meta.overlay && tracks.length > 1 ? meta.trackColours[t.index] : BONE;
    const colour = (p) => (t.pointLabels && labelColour(t.pointLabels[p])) || plain;
    // Overlaid tracks after the first are dashed, so they stay apart even in label colours.
    ctx.setLineDash(meta.overlay && k > 0 ? [6, 4] : []);
    ctx.lineCap = 'round';
    const bones = new Map();
    for (let p = 0; p < t.points; p++) {
      if (t.parents[p] === null) continue;
      const col = colour(p);
      if (!bones.has(col)) bones.set(col, []);
      bones.get(col).push(p);
    }
    for (const [col, children] of bones) stroke(col, 2.5, () => children.forEach((p) => segment(pts[t.parents[p]], pts[p])));
    ctx.setLineDash([]);
    const feet = new Set(t.feet);
    for (let p = 0; p < t.points; p++) {
      const s = pts[p];
      if (!s || t.endSite[p]) continue;
      projected.push({ x: s[0], y: s[1], point: p, name: t.names[p], track: t, frame: f });
      ctx.fillStyle = colour(p);
      if (feet.has(p)) {
        ctx.strokeStyle = colour(p);
        ctx.lineWidth = 2;
        ctx.strokeRect(s[0] - 4.5, s[1] - 4.5, 9, 9);
      } else {
        ctx.beginPath();
        ctx.arc(s[0], s[1], 3, 0, 2 * Math.PI);
        ctx.fill();
      }
    }
  }

  function drawView(view) {
    const r = view.rect, c = camera(view, r);
    ctx.save();
    ctx.beginPath();
    ctx.rect(r.x, r.y, r.w, r.h);
    ctx.clip();
    // Frame labels tint the view (the first track's label, which is also written in the corner).
    const first = view.tracks[0];
    const label = first.frameLabels ? first.frameLabels[frameOf(first, time)] : null;
    const tint = labelColour(label);
    if (tint) {
      ctx.globalAlpha = 0.12;
      ctx.fillStyle = tint;
      ctx.fillRect(r.x, r.y, r.w, r.h);
      ctx.globalAlpha = 1;
    }
    drawGrid(view, c);
    view.tracks.forEach((t, k) => drawTrack(view, c, t, k));
    ctx.fillStyle = '#222';
    ctx.font = '12px system-ui, sans-serif';
    let y = r.y + 18;
    for (const t of view.tracks) {
      const f = frameOf(t, time);
      const li = t.frameLabels ? t.frameLabels[f] : null;
      const l = li !== null && meta.legend[li] ? meta.legend[li].name : null;
      ctx.fillText(`${t.title}  frame ${f + 1}/${t.frames}  ${+t.fps.toFixed(2)} fps${l ? '  · ' + l : ''}`, r.x + 8, y);
      y += 17;
    }
    ctx.restore();
    stroke('#ccc', 1, () => {
      if (r.x > 0) segment([r.x + 0.5, r.y], [r.x + 0.5, r.y + r.h]);
      if (r.y > 0) segment([r.x, r.y + 0.5], [r.x + r.w, r.y + 0.5]);
    });
  }

  // Frame labels as a timeline under the picture: one row per labelled track, runs of equal
  // labels as coloured bars, and the current time as a cursor.
  function labelRuns(t) {
    const runs = [];
    let start = 0;
    for (let f = 1; f <= t.frames; f++) {
      if (f === t.frames || t.frameLabels[f] !== t.frameLabels[start]) {
        const colour = labelColour(t.frameLabels[start]);
        if (colour) runs.push([start / t.fps, f / t.fps, colour]);
        start = f;
      }
    }
    return runs;
  }

  function drawStrip() {
    const strip = $('strip');
    if (strip.hidden) return;
    const sctx = strip.getContext('2d');
    const w = Math.max(1, strip.clientWidth), h = Math.max(1, strip.clientHeight);
    const dpr = window.devicePixelRatio || 1;
    if (strip.width !== Math.round(w * dpr) || strip.height !== Math.round(h * dpr)) {
      strip.width = Math.round(w * dpr);
      strip.height = Math.round(h * dpr);
    }
    sctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    sctx.fillStyle = '#eee';
    sctx.fillRect(0, 0, w, h);
    const rows = tracks.filter((t) => t.runs);
    rows.forEach((t, k) => {
      const y0 = (k * h) / rows.length, y1 = ((k + 1) * h) / rows.length;
      for (const [a, b, colour] of t.runs) {
        sctx.fillStyle = colour;
        sctx.fillRect((a / duration) * w, y0, Math.max(1, ((b - a) / duration) * w), y1 - y0);
      }
    });
    sctx.fillStyle = '#000';
    sctx.fillRect(Math.min(w - 2, (time / duration) * w), 0, 2, h);
  }

  function setupStrip() {
    const strip = $('strip');
    tracks.forEach((t) => { if (t.frameLabels) t.runs = labelRuns(t); });
    const rows = tracks.filter((t) => t.runs).length;
    if (rows === 0) return;
    strip.style.height = `${Math.min(4, rows) * 6 + 4}px`;
    strip.hidden = false;
    const seek = (e) => {
      const box = strip.getBoundingClientRect();
      playing = false;
      time = Math.max(0, Math.min(duration - 1e-9, ((e.clientX - box.left) / box.width) * duration));
      dirty = true;
    };
    strip.addEventListener('pointerdown', seek);
    strip.addEventListener('pointermove', (e) => { if (e.buttons) seek(e); });
  }

  // Columns and rows for n views: the layout whose cells fit the largest landscape (4:3) picture.
  function grid(n, w, h) {
    let best = [n, 1], score = -1;
    for (let cols = 1; cols <= n; cols++) {
      const rows = Math.ceil(n / cols);
      const s = Math.min(w / cols / 4 * 3, h / rows);
      if (s > score) { score = s; best = [cols, rows]; }
    }
    return best;
  }

  function draw() {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, canvas.clientWidth), h = Math.max(1, canvas.clientHeight);
    if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
      canvas.width = Math.round(w * dpr);
      canvas.height = Math.round(h * dpr);
    }
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = BACKGROUND;
    ctx.fillRect(0, 0, w, h);
    projected = [];
    const [cols, rows] = grid(views.length, w, h);
    views.forEach((v, i) => {
      const vw = w / cols, vh = h / rows;
      v.rect = { x: (i % cols) * vw, y: Math.floor(i / cols) * vh, w: vw, h: vh };
      drawView(v);
    });
    // The hovered joint stays marked while it moves.
    if (hovered) hovered = projected.find((p) => p.track === hovered.track && p.point === hovered.point) || null;
    if (hovered) {
      ctx.strokeStyle = '#d00';
      ctx.lineWidth = 2;
      ctx.beginPath();
      ctx.arc(hovered.x, hovered.y, 7, 0, 2 * Math.PI);
      ctx.stroke();
    }
    drawStrip();
    const slider = $('slider');
    slider.value = Math.min(steps - 1, Math.floor(time * maxFps + 1e-6));
    $('clock').textContent = `${time.toFixed(2)} s`;
    $('play').textContent = playing ? 'Pause' : 'Play';
    dirty = false;
  }

  // ---- controls ------------------------------------------------------------------------------

  function setPlaying(p) { playing = p; dirty = true; }
  function stepBy(n) { setPlaying(false); time = Math.max(0, Math.min(duration - 1e-9, (Math.floor(time * maxFps + 1e-6) + n) / maxFps)); }
  function resetCamera() { Object.assign(cam, { yaw: defaultYaw, pitch: DEFAULT_PITCH, zoom: 1, panX: 0, panY: 0 }); dirty = true; }

  function setupControls() {
    // Blurred after a click, so space (our play key) never also presses the focused button.
    $('play').addEventListener('click', () => { setPlaying(!playing); $('play').blur(); });
    const slider = $('slider');
    slider.max = String(steps - 1);
    // Scrubbing pauses: the picture shows the frame under the thumb.
    slider.addEventListener('input', () => { playing = false; time = Number(slider.value) / maxFps; dirty = true; });
    const select = $('speed');
    const speeds = [0.1, 0.25, 0.5, 1, 2, 4];
    if (!speeds.includes(speed)) speeds.push(speed);
    speeds.sort((a, b) => a - b);
    for (const s of speeds) {
      const o = document.createElement('option');
      o.value = String(s);
      o.textContent = `${s}×`;
      o.selected = s === speed;
      select.appendChild(o);
    }
    select.addEventListener('change', () => { speed = Number(select.value); });
    const followBox = $('follow');
    followBox.checked = follow;
    followBox.addEventListener('change', () => { follow = followBox.checked; cam.panX = cam.panY = 0; dirty = true; });
    $('reset').addEventListener('click', resetCamera);
    window.addEventListener('keydown', (e) => {
      // Keys typed into the speed list stay there.
      if (e.target instanceof HTMLSelectElement) return;
      // The focused slider steps with the arrows itself.
      if (e.target === slider && e.key.startsWith('Arrow')) return;
      if (e.key === ' ') { setPlaying(!playing); e.preventDefault(); }
      else if (e.key === 'ArrowRight') { stepBy(1); e.preventDefault(); }
      else if (e.key === 'ArrowLeft') { stepBy(-1); e.preventDefault(); }
      else if (e.key === 'Home') { time = 0; dirty = true; }
      else if (e.key === 'f') { followBox.checked = follow = !follow; dirty = true; }
      else if (e.key === 'r') resetCamera();
    });
    window.addEventListener('resize', () => { dirty = true; });

    let drag = null;
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
      // Capture keeps a drag going outside the canvas; a pointer that is already gone cannot be
      // captured, and the drag then simply ends at the canvas edge.
      try { canvas.setPointerCapture(e.pointerId); } catch (_) { /* see above */ }
      canvas.classList.add('dragging');
    });
    canvas.addEventListener('pointerup', () => { drag = null; canvas.classList.remove('dragging'); });
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('pointermove', (e) => {
      const box = canvas.getBoundingClientRect();
      if (drag) {
        const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
        drag.x = e.clientX; drag.y = e.clientY;
        if (drag.pan) {
          const scale = 2 / (views[0].rect.h * cam.zoom);
          cam.panX -= dx * scale;
          cam.panY += dy * scale;
        } else {
          cam.yaw -= dx * 0.01;
          cam.pitch = Math.max(-1.45, Math.min(1.45, cam.pitch + dy * 0.01));
        }
        hideTip();
        dirty = true;
        return;
      }
      hover(e.clientX - box.left, e.clientY - box.top);
    });
    canvas.addEventListener('pointerleave', hideTip);
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      cam.zoom = Math.max(0.05, Math.min(50, cam.zoom * Math.exp(-e.deltaY * 0.0015)));
      dirty = true;
    }, { passive: false });
  }

  function hideTip() {
    $('tip').hidden = true;
    if (hovered) { hovered = null; dirty = true; }
  }

  // The joint nearest the pointer (within 10 px) gets a tooltip with its name and track.
  function hover(x, y) {
    let best = null, bestD = 100;
    for (const p of projected) {
      const d = (p.x - x) ** 2 + (p.y - y) ** 2;
      if (d < bestD) { bestD = d; best = p; }
    }
    if (!best) { hideTip(); return; }
    const tip = $('tip');
    tip.textContent = `${best.name}\n${best.track.title} · frame ${best.frame + 1}`;
    tip.hidden = false;
    tip.style.left = `${x + 14}px`;
    tip.style.top = `${y + 10}px`;
    if (!hovered || hovered.point !== best.point || hovered.track !== best.track) dirty = true;
    hovered = best;
  }

  function setupLegend() {
    const box = $('legend');
    const rows = meta.legend.map((l) => [l.colour, l.name]);
    // Overlaid tracks are told apart by colour when nothing else colours them, and always by
    // line style: list them too.
    if (meta.overlay && tracks.length > 1) {
      const labelled = tracks.some((t) => t.pointLabels);
      tracks.forEach((t, i) => rows.push([labelled ? BONE : meta.trackColours[i], `${t.title} (${i > 0 ? 'dashed' : 'solid'})`]));
    }
    for (const [colour, name] of rows) {
      const row = document.createElement('div');
      const swatch = document.createElement('i');
      swatch.style.background = colour;
      const text = document.createElement('span');
      text.textContent = name;
      row.append(swatch, text);
      box.appendChild(row);
    }
    box.hidden = rows.length === 0;
  }

  // ---- playback: fps-correct by accumulating real elapsed time, not counting animation frames --

  let last = null, stopped = false;
  function tick(now) {
    if (last !== null && playing) {
      time += (Math.min(now - last, 250) / 1000) * speed;
      if (time >= duration) time %= duration;
      dirty = true;
    }
    last = now;
    if (dirty) draw();
    if (!stopped) requestAnimationFrame(tick);
  }

  // ---- self test: two frames drawn, pixels counted, result as JSON for the browser test ---------

  // "Ink" is every pixel unlike the most common colour (the background, tinted or not).
  function ink(px) {
    const counts = new Map();
    for (let i = 0; i < px.length; i += 4 * 7) {
      const c = (px[i] << 16) | (px[i + 1] << 8) | px[i + 2];
      counts.set(c, (counts.get(c) || 0) + 1);
    }
    let bg = 0, most = -1;
    for (const [c, n] of counts) if (n > most) { most = n; bg = c; }
    let n = 0;
    for (let i = 0; i < px.length; i += 4) {
      const d = Math.abs(px[i] - (bg >> 16)) + Math.abs(px[i + 1] - ((bg >> 8) & 255)) + Math.abs(px[i + 2] - (bg & 255));
      if (d > 30) n++;
    }
    return n;
  }

  function selftest() {
    const shot = (t) => {
      time = t;
      draw();
      return ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    };
    const a = shot(0), b = shot(duration / 2);
    let diff = 0;
    for (let i = 0; i < a.length; i += 4) {
      if (a[i] !== b[i] || a[i + 1] !== b[i + 1] || a[i + 2] !== b[i + 2]) diff++;
    }
    // Hovering the first drawn joint must name it.
    const target = projected[0];
    hover(target.x, target.y);
    const tip = $('tip').hidden ? '' : $('tip').textContent;
    // Drag to orbit, shift-drag to pan, wheel to zoom, space to play: the handlers run cleanly.
    const was = { ...cam };
    const at = (x, y, extra) => Object.assign({ clientX: x, clientY: y, pointerId: 1, bubbles: true }, extra);
    canvas.dispatchEvent(new PointerEvent('pointerdown', at(100, 100)));
    canvas.dispatchEvent(new PointerEvent('pointermove', at(140, 110)));
    canvas.dispatchEvent(new PointerEvent('pointerup', at(140, 110)));
    canvas.dispatchEvent(new PointerEvent('pointerdown', at(100, 100, { shiftKey: true })));
    canvas.dispatchEvent(new PointerEvent('pointermove', at(90, 120, { shiftKey: true })));
    canvas.dispatchEvent(new PointerEvent('pointerup', at(90, 120)));
    canvas.dispatchEvent(new WheelEvent('wheel', { deltaY: -200, bubbles: true, cancelable: true }));
    window.dispatchEvent(new KeyboardEvent('keydown', { key: ' ', bubbles: true }));
    const controls = { orbited: cam.yaw !== was.yaw && cam.pitch !== was.pitch, panned: cam.panX !== was.panX, zoomed: cam.zoom > was.zoom, played: playing };
    draw();
    playing = false;
    return {
      controls, hover: tip, hoverWanted: `${target.name}\n${target.track.title}`,
      width: canvas.width, height: canvas.height, tracks: tracks.length, views: views.length,
      frames: tracks.map((t) => [frameOf(t, 0), frameOf(t, duration / 2)]),
      ink: [ink(a), ink(b)], diff,
      // Relative to each track's level size: Float32 rounding only, far below one level.
      probeError: Math.max(...tracks.map((t) => t.probeError / Math.max(...t.step, 1e-30))),
    };
  }

  function report(result) {
    const pre = $('selftest');
    pre.textContent = JSON.stringify(Object.assign(result, { errors: window.viewerErrors }));
  }

  async function main() {
    const started = performance.now();
    const bytes = await inflate(document.getElementById('data').textContent);
    if (bytes.length !== meta.dataBytes) throw new Error(`motion data is ${bytes.length} bytes, expected ${meta.dataBytes}`);
    tracks.forEach((t, i) => { t.index = i; decodeTrack(t, bytes); });
    if (meta.overlay) views.push({ tracks, m: measure(tracks) });
    else for (const t of tracks) views.push({ tracks: [t], m: measure([t]) });
    const loadMs = performance.now() - started;
    // Walks go left to right: look at the first track's path from its side.
    const t0 = tracks[0], a = root(t0, 0), b = root(t0, t0.frames - 1);
    const dx = b[0] - a[0], dz = b[2] - a[2];
    if (Math.hypot(dx, dz) > 0.3 * views[0].m.body) defaultYaw = Math.atan2(-dz, dx);
    resetCamera();
    setupControls();
    setupLegend();
    setupStrip();
    if (location.hash === '#selftest') {
      playing = false;
      const result = selftest();
      // Then two animation frames 100 ms apart: the clock advances by real time times speed
      // (driven by hand: headless browsers schedule animation frames unpredictably).
      stopped = true;
      time = 0;
      playing = true;
      tick(1000);
      tick(1100);
      result.controls.advanced = Math.abs(time - ((0.1 * speed) % duration)) < 1e-9;
      result.loadMs = Math.round(loadMs);
      report(result);
      return;
    }
    requestAnimationFrame(tick);
  }

  main().catch((e) => {
    const m = $('message');
    m.textContent = `cannot show the motion: ${e && e.message ? e.message : e}`;
    m.hidden = false;
    console.error(m.textContent);
    if (location.hash === '#selftest') report({ failed: true });
  });
})();
