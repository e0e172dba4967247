// digiteyes UI: polls /api/state and draws the hand, the 3D mouse, the camera frame, the
// link's figures and the states. No libraries: the 3D view is a painter's-algorithm canvas.
"use strict";

const POLL_MS = 50;
const $ = (id) => document.getElementById(id);

let info = { labels: [], free: [], source: "" };
let snap = null;
let lastSeq = -1;
let cameraFrame = null;
let cameraLoading = false;
const trail = [];

// ---- small vector helpers (world: mm, z up) ----
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a) => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return mul(a, 1 / l); };

// ---- the orbiting view ----
const HOME = { az: -Math.PI / 2 - 0.5, el: 0.55, dist: 320 };
const view = { ...HOME, target: null };

function camera(canvas) {
  const t = view.target || [0, 0, 0];
  const ce = Math.cos(view.el);
  const eye = add(t, mul([ce * Math.cos(view.az), ce * Math.sin(view.az), Math.sin(view.el)], view.dist));
  const f = norm(sub(t, eye));
  let r = cross(f, [0, 0, 1]);
  if (Math.hypot(...r) < 1e-6) r = [1, 0, 0];
  r = norm(r);
  const u = cross(r, f);
  const F = 1.1 * Math.min(canvas.width, canvas.height);
  const cx = canvas.width / 2, cy = canvas.height / 2;
  return {
    eye, f,
    project(p) {
      const v = sub(p, eye);
      const z = dot(v, f);
      return { x: cx + (F * dot(v, r)) / z, y: cy - (F * dot(v, u)) / z, z, s: F / z };
    },
  };
}

function shade(base, k) {
  const c = base.map((v) => Math.round(Math.min(255, v * k)));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

function drawHand() {
  const canvas = $("hand3d");
  const ctx = canvas.getContext("2d");
  ctx.fillStyle = "#e9edf2";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  const shapes = (snap && snap.shapes) || [];
  if (!shapes.length) {
    ctx.fillStyle = "#667";
    ctx.font = "16px sans-serif";
    ctx.fillText(snap && snap.state ? "the state does not fit the model" : "waiting for states…", 20, 30);
    document.body.dataset.shapesDrawn = "0";
    return;
  }
  const palm = shapes.find((s) => s.kind === "box");
  if (!view.target) view.target = palm ? palm.centre.slice() : shapes[0].a.slice();
  const cam = camera(canvas);
  const items = [];
  // The table set-ups put the palm above z = 0 (a curled fingertip may dip below it: the
  // synthetic scenes have no real table); then the table and the mouse's pole are drawn.
  const onTable = !!palm &&
    palm.centre[2] - [0, 1, 2].reduce((z, k) => z + Math.abs(palm.axes[k][2] * palm.half[k]), 0) > 0;
  if (onTable) drawGrid(ctx, cam);
  const light = norm([0.3, -0.5, 1]);
  const skin = [228, 180, 150];
  for (const s of shapes) {
    if (s.kind === "capsule") {
      const a = cam.project(s.a), b = cam.project(s.b);
      if (a.z <= 1 || b.z <= 1) continue;
      const depth = (a.z + b.z) / 2;
      items.push({
        depth,
        draw() {
          const w = s.r * (a.s + b.s);
          ctx.lineCap = "round";
          ctx.strokeStyle = "rgba(60,40,30,0.9)";
          ctx.lineWidth = w + 2;
          ctx.beginPath(); ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y); ctx.stroke();
          ctx.strokeStyle = shade(skin, 1.15 - 0.25 * Math.min(1, (depth - view.dist + 150) / 300));
          ctx.lineWidth = w;
          ctx.beginPath(); ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y); ctx.stroke();
        },
      });
    } else if (s.kind === "box") {
      for (let k = 0; k < 3; k++) {
        for (const sign of [-1, 1]) {
          const n = mul(s.axes[k], sign);
          const fc = add(s.centre, mul(s.axes[k], sign * s.half[k]));
          if (dot(n, sub(cam.eye, fc)) <= 0) continue;
          const i = (k + 1) % 3, j = (k + 2) % 3;
          const corners = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([p, q]) =>
            cam.project(add(fc, add(mul(s.axes[i], p * s.half[i]), mul(s.axes[j], q * s.half[j])))));
          if (corners.some((c) => c.z <= 1)) continue;
          const depth = cam.project(fc).z;
          const lit = 0.55 + 0.45 * Math.max(0, dot(n, light));
          items.push({
            depth: depth + 40, // the palm is drawn behind the fingers that rest on it
            draw() {
              ctx.beginPath();
              corners.forEach((c, m) => (m ? ctx.lineTo(c.x, c.y) : ctx.moveTo(c.x, c.y)));
              ctx.closePath();
              ctx.fillStyle = shade(skin, lit);
              ctx.fill();
              ctx.strokeStyle = "rgba(60,40,30,0.9)";
              ctx.lineWidth = 1;
              ctx.stroke();
            },
          });
        }
      }
    }
  }
  const m = snap.mouse;
  if (m && onTable) {
    const base = cam.project([m.x_mm, m.y_mm, 0]);
    const top = cam.project([m.x_mm, m.y_mm, m.height_mm]);
    if (base.z > 1 && top.z > 1) {
      items.push({
        depth: Math.min(base.z, top.z) - 200, // the pole is the cursor: always in front
        draw() {
          ctx.strokeStyle = "#e67e22";
          ctx.lineWidth = 4;
          ctx.beginPath(); ctx.moveTo(base.x, base.y); ctx.lineTo(top.x, top.y); ctx.stroke();
          ctx.fillStyle = "#e67e22";
          ctx.beginPath(); ctx.arc(top.x, top.y, 7, 0, 2 * Math.PI); ctx.fill();
          ctx.beginPath(); ctx.ellipse(base.x, base.y, 14, 6, 0, 0, 2 * Math.PI); ctx.fill();
        },
      });
    }
  }
  items.sort((p, q) => q.depth - p.depth);
  for (const it of items) it.draw();
  document.body.dataset.shapesDrawn = String(shapes.length);
}

function drawGrid(ctx, cam) {
  const t = view.target;
  const step = 20, half = 200;
  const x0 = Math.round(t[0] / step) * step, y0 = Math.round(t[1] / step) * step;
  ctx.strokeStyle = "rgba(90,110,130,0.35)";
  ctx.lineWidth = 1;
  for (let d = -half; d <= half; d += step) {
    for (const [p, q] of [[[x0 + d, y0 - half, 0], [x0 + d, y0 + half, 0]], [[x0 - half, y0 + d, 0], [x0 + half, y0 + d, 0]]]) {
      const a = cam.project(p), b = cam.project(q);
      if (a.z <= 1 || b.z <= 1) continue;
      ctx.beginPath(); ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y); ctx.stroke();
    }
  }
}

// ---- the 3D mouse: a top view of the table, the pole's height and the two buttons ----
function drawMouse() {
  const canvas = $("mouse");
  const ctx = canvas.getContext("2d");
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  const m = snap && snap.mouse;
  const W = 260, H = 240, ox = 10, oy = 10, range = 100; // ±100 mm around the rest position
  ctx.strokeStyle = "#bbb";
  ctx.strokeRect(ox, oy, W, H);
  ctx.fillStyle = "#888";
  ctx.font = "11px sans-serif";
  ctx.fillText("table, top view (±100 mm)", ox + 4, oy + H - 6);
  if (!m) return;
  if (!trail.length || trail[trail.length - 1][0] !== m.x_mm || trail[trail.length - 1][1] !== m.y_mm) {
    trail.push([m.x_mm, m.y_mm]);
    if (trail.length > 90) trail.shift();
  }
  const px = (x) => ox + W / 2 + (x / range) * (W / 2);
  const py = (y) => oy + H / 2 - (y / range) * (H / 2);
  ctx.strokeStyle = "rgba(230,126,34,0.5)";
  ctx.beginPath();
  trail.forEach(([x, y], i) => (i ? ctx.lineTo(px(x), py(y)) : ctx.moveTo(px(x), py(y))));
  ctx.stroke();
  ctx.fillStyle = "#e67e22";
  ctx.beginPath(); ctx.arc(px(m.x_mm), py(m.y_mm), 6, 0, 2 * Math.PI); ctx.fill();
  // Height bar: 0..80 mm.
  const bx = ox + W + 20, bh = 180, top = oy + 10;
  ctx.strokeStyle = "#bbb";
  ctx.strokeRect(bx, top, 24, bh);
  const h = Math.max(0, Math.min(1, m.height_mm / 80));
  ctx.fillStyle = "#e67e22";
  ctx.fillRect(bx, top + bh * (1 - h), 24, bh * h);
  ctx.fillStyle = "#555";
  ctx.fillText("height", bx - 4, top + bh + 14);
  // Buttons.
  const names = ["finger 4", "thumb"];
  (m.buttons || []).forEach((on, i) => {
    const cx = bx + 70, cy = top + 30 + i * 70;
    ctx.fillStyle = on ? "#c0392b" : "#ddd";
    ctx.beginPath(); ctx.arc(cx, cy, 18, 0, 2 * Math.PI); ctx.fill();
    ctx.fillStyle = "#555";
    ctx.fillText(names[i], cx - 22, cy + 34);
  });
}

// ---- the text panels ----
function setLink(rows) {
  const body = $("link").tBodies[0];
  body.innerHTML = "";
  for (const [name, value] of rows) {
    const tr = body.insertRow();
    tr.insertCell().textContent = name;
    const td = tr.insertCell();
    td.className = "value";
    td.textContent = value;
  }
}

function updatePanels() {
  const s = snap.state;
  const status = $("status");
  if (snap.no_signal) {
    status.className = "badge nosignal";
    status.textContent = s ? "NO SIGNAL" : "WAITING";
  } else if (s && s.lost) {
    status.className = "badge lost";
    status.textContent = "LOST TRACK";
  } else {
    status.className = "badge tracking";
    status.textContent = "TRACKING";
  }
  $("frame").textContent = s
    ? `frame ${s.frame} · rms ${Number.isFinite(s.rms_px) ? s.rms_px.toFixed(2) : "–"} px · ` +
      `${s.features_found}/${s.features_expected} features · ${s.iterations} iterations`
    : "no state yet";
  document.body.dataset.frame = s ? String(s.frame) : "";
  document.title = s ? `digiteyes · frame ${s.frame}` : "digiteyes";

  const l = snap.link;
  const rows = [
    ["states received", l.states],
    ["states/s (last 2 s)", l.states_per_s.toFixed(1)],
    ["lost-track states", l.lost_states],
    ["frames dropped", l.dropped],
  ];
  for (const [why, n] of Object.entries(l.drops)) rows.push([` · ${why}`, n]);
  rows.push(["CRC errors (this host)", l.crc_errors], ["framing errors (this host)", l.framing_errors]);
  if (l.board) {
    rows.push(["board: frames tracked", l.board.frames], ["board: CRC errors", l.board.link.crc_errors],
      ["board: framing errors", l.board.link.framing_errors]);
  }
  if (l.unreadable) rows.push(["unreadable datagrams", l.unreadable]);
  if (snap.age_s !== null) rows.push(["last state", `${snap.age_s.toFixed(1)} s ago`]);
  setLink(rows);

  const body = $("states").tBodies[0];
  const q = s ? s.q : [];
  const n = Math.max(info.labels.length, q.length);
  if (body.rows.length !== n) {
    body.innerHTML = "";
    for (let i = 0; i < n; i++) {
      const tr = body.insertRow();
      tr.dataset.state = String(i);
      if (info.free.includes(i)) tr.className = "free";
      tr.insertCell().textContent = info.labels[i] || `q${i}`;
      tr.insertCell().className = "value";
    }
  }
  for (let i = 0; i < n; i++) {
    const v = q[i];
    body.rows[i].cells[1].textContent = v === undefined || v === null ? "–" : v.toFixed(3);
  }

  const m = snap.mouse;
  $("mouse-values").textContent = m
    ? `base (${m.x_mm.toFixed(1)}, ${m.y_mm.toFixed(1)}) mm · height ${m.height_mm.toFixed(1)} mm ` +
      `(fingertip at z ${m.tip_z_mm.toFixed(1)} mm) · ` +
      `buttons: finger 4 ${m.buttons[0] ? "DOWN" : "up"}, thumb ${m.buttons[1] ? "DOWN" : "up"}`
    : "no mouse reading: it needs the built-in hand model";

  if (snap.camera_frame !== null && snap.camera_frame !== cameraFrame && !cameraLoading) {
    cameraFrame = snap.camera_frame;
    cameraLoading = true;
    const img = $("camera");
    img.onload = img.onerror = () => { cameraLoading = false; };
    img.src = `/frame.png?frame=${cameraFrame}&t=${Date.now()}`;
    img.hidden = false;
    $("no-camera").hidden = true;
  }
}

async function poll() {
  try {
    const r = await fetch("/api/state", { cache: "no-store" });
    if (r.ok) {
      snap = await r.json();
      if (snap.seq !== lastSeq) {
        lastSeq = snap.seq;
        updatePanels();
        drawHand();
        drawMouse();
      } else {
        updatePanels();
      }
    }
  } catch (e) {
    $("status").className = "badge nosignal";
    $("status").textContent = "UI SERVER GONE";
  }
  setTimeout(poll, POLL_MS);
}

// ---- orbit and zoom ----
function setupControls() {
  const c = $("hand3d");
  let drag = null;
  c.addEventListener("mousedown", (e) => { drag = [e.clientX, e.clientY]; });
  window.addEventListener("mouseup", () => { drag = null; });
  window.addEventListener("mousemove", (e) => {
    if (!drag) return;
    view.az -= (e.clientX - drag[0]) * 0.01;
    view.el = Math.max(-1.5, Math.min(1.5, view.el + (e.clientY - drag[1]) * 0.01));
    drag = [e.clientX, e.clientY];
    if (snap) drawHand();
  });
  c.addEventListener("wheel", (e) => {
    e.preventDefault();
    view.dist = Math.max(120, Math.min(3000, view.dist * Math.exp(e.deltaY * 0.001)));
    if (snap) drawHand();
  }, { passive: false });
  c.addEventListener("dblclick", () => {
    Object.assign(view, HOME, { target: null });
    if (snap) drawHand();
  });
}

async function start() {
  setupControls();
  try {
    const r = await fetch("/api/model", { cache: "no-store" });
    if (r.ok) info = await r.json();
  } catch (e) { /* the poll loop reports a missing server */ }
  $("source").textContent = info.source;
  poll();
}

start();
