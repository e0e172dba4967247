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

// How the hand is drawn for a status: solid while tracked; ghosted while lost (the board
// holds the last good state); not at all while searching (the state is no estimate).
function handLook(state) {
  const status = trackStatus(state);
  if (status === "searching") return "hidden";
  return status === "lost" ? "ghost" : "solid";
}

// A state's status word; a state without one (an older source) is lost or tracking.
function trackStatus(state) {
  if (!state) return "";
  if (state.status) return state.status;
  return state.lost ? "lost" : "tracking";
}

function drawHand() {
  const canvas = $("hand3d");
  const ctx = canvas.getContext("2d");
  ctx.fillStyle = "#e9edf2";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  const shapes = (snap && snap.shapes) || [];
  const look = snap && snap.state ? handLook(snap.state) : "solid";
  document.body.dataset.hand = shapes.length ? look : "none";
  if (!shapes.length || look === "hidden") {
    ctx.fillStyle = "#667";
    ctx.font = "16px sans-serif";
    ctx.fillText(
      !snap || !snap.state ? "waiting for states…"
        : look === "hidden" ? "searching for the hand…" : "the state does not fit the model",
      20, 30);
    document.body.dataset.shapesDrawn = "0";
    document.body.dataset.ghostsDrawn = "0";
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
  document.body.dataset.ghostsDrawn = String(drawGhosts(ctx, cam, snap.ghosts || []));
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
  ctx.save();
  if (look === "ghost") ctx.globalAlpha = 0.3;
  for (const it of items) it.draw();
  ctx.restore();
  if (look === "ghost") {
    ctx.fillStyle = "#c0392b";
    ctx.font = "16px sans-serif";
    ctx.fillText("lost: the last good state, held", 20, 30);
  }
  document.body.dataset.shapesDrawn = String(shapes.length);
}

// The tracker's other hypotheses (rank 1 and up), behind the hand: thin, pale outlines.
// Returns how many were drawn.
function drawGhosts(ctx, cam, ghosts) {
  let drawn = 0;
  ctx.save();
  ctx.lineCap = "round";
  for (const g of ghosts) {
    const shapes = g.shapes || [];
    if (!shapes.length) continue;
    ctx.strokeStyle = "rgba(70,100,160,0.35)";
    ctx.lineWidth = 1.5;
    for (const s of shapes) {
      if (s.kind === "capsule") {
        const a = cam.project(s.a), b = cam.project(s.b);
        if (a.z <= 1 || b.z <= 1) continue;
        ctx.beginPath(); ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y); ctx.stroke();
      } else if (s.kind === "box") {
        const corner = (i, j, k) => cam.project(add(s.centre, add(mul(s.axes[0], i * s.half[0]),
          add(mul(s.axes[1], j * s.half[1]), mul(s.axes[2], k * s.half[2])))));
        for (const [p, q] of BOX_EDGES) {
          const a = corner(...p), b = corner(...q);
          if (a.z <= 1 || b.z <= 1) continue;
          ctx.beginPath(); ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y); ctx.stroke();
        }
      }
    }
    drawn += 1;
  }
  ctx.restore();
  return drawn;
}

// A box's 12 edges, as pairs of corners (signs along its three axes).
const BOX_EDGES = (() => {
  const edges = [];
  for (const i of [-1, 1]) for (const j of [-1, 1]) {
    edges.push([[-1, i, j], [1, i, j]], [[i, -1, j], [i, 1, j]], [[i, j, -1], [i, j, 1]]);
  }
  return edges;
})();

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

// ---- the 3D mouse: the thesis' scene (Sec. 4.3.4, Figs. 4.9 and 4.13) ----
// A ground plane, the pole standing on it with its shadow, the cursor at the pole's top, and
// spheres to select: a thumb click with the cursor inside a sphere selects it (highlighted, a
// line from the cursor to it), a thumb click anywhere else or a finger-4 click drops the
// selection. Scene units are the pole's millimetres: base (x, y) on the ground, height up.
// The spheres sit where the demo's trial (`mouse-thesis`) clicks: A where the raised finger
// holds during the thumb's clicks, B on the path of its last thumb click; C is never clicked.
const SPHERES = [
  { name: "A", centre: [0, 0, 48], r: 12, colour: [70, 130, 200] },
  { name: "B", centre: [-14, 22, 12], r: 12, colour: [90, 170, 90] },
  { name: "C", centre: [40, 45, 30], r: 12, colour: [170, 110, 190] },
];
const GROUND_HALF_MM = 75;
const GROUND_CHECK_MM = 15;
// Towards the light: the shadows fall away from it, onto the ground.
const LIGHT = norm([-0.45, 0.55, 1]);
const SCENE_EYE = [-45, -170, 125];
const SCENE_TARGET = [0, 14, 20];
const THUMB = 1, FINGER4 = 0;
// What the page saw of the mouse; mirrored as data-* attributes on <body> for tests.
const mouseState = {
  buttons: null, selected: null, thumbPresses: 0, finger4Presses: 0, hovered: 0, events: [],
};

function sceneCamera(canvas) {
  const eye = SCENE_EYE;
  const f = norm(sub(SCENE_TARGET, eye));
  const r = norm(cross(f, [0, 0, 1]));
  const u = cross(r, f);
  const F = 1.2 * Math.min(canvas.width, canvas.height);
  const cx = canvas.width / 2, cy = canvas.height / 2 + 10;
  return {
    project(p) {
      const v = sub(p, eye);
      const z = dot(v, f);
      return { x: cx + (F * dot(v, r)) / z, y: cy - (F * dot(v, u)) / z, z, s: F / z };
    },
  };
}

// Where a point's shadow falls on the ground (z = 0).
const shadowOf = (p) => sub(p, mul(LIGHT, p[2] / LIGHT[2]));

// The sphere the cursor is inside, if any (the nearest centre).
function sphereAt(cursor) {
  let best = null, bestD = Infinity;
  for (const s of SPHERES) {
    const d = Math.hypot(...sub(cursor, s.centre));
    if (d <= s.r && d < bestD) { best = s; bestD = d; }
  }
  return best;
}

// Takes in a new mouse reading: counts presses (a button going down) and selects or drops.
function updateSelection(m) {
  const cursor = [m.x_mm, m.y_mm, m.height_mm];
  const over = sphereAt(cursor);
  if (over) mouseState.hovered += 1;
  const before = mouseState.buttons;
  const log = (event) => {
    mouseState.events.push(event);
    if (mouseState.events.length > 16) mouseState.events.shift();
  };
  if (before) {
    if (m.buttons[THUMB] && !before[THUMB]) {
      mouseState.thumbPresses += 1;
      if (over) log(`select:${over.name}`);
      else if (mouseState.selected) log("drop:thumb");
      mouseState.selected = over ? over.name : null;
    }
    if (m.buttons[FINGER4] && !before[FINGER4]) {
      mouseState.finger4Presses += 1;
      if (mouseState.selected) log("drop:finger4");
      mouseState.selected = null;
    }
  }
  mouseState.buttons = m.buttons.slice();
  const body = document.body.dataset;
  body.mouseSelected = mouseState.selected || "";
  body.mouseHover = over ? over.name : "";
  body.mouseHovered = String(mouseState.hovered);
  body.thumbPresses = String(mouseState.thumbPresses);
  body.finger4Presses = String(mouseState.finger4Presses);
  body.mouseEvents = mouseState.events.join(" ");
  const sel = SPHERES.find((s) => s.name === mouseState.selected);
  $("mouse-selection").textContent = sel
    ? `selected: sphere ${sel.name} at (${sel.centre.join(", ")}) mm`
    : over ? `cursor inside sphere ${over.name}: click the thumb to select it` : "nothing selected";
}

function drawMouse() {
  const canvas = $("mouse");
  const ctx = canvas.getContext("2d");
  ctx.fillStyle = "#f7f5ee";
  ctx.fillRect(0, 0, canvas.width, canvas.height);
  const m = snap && snap.mouse;
  if (m) {
    updateSelection(m);
    const last = trail[trail.length - 1];
    if (!last || last[0] !== m.x_mm || last[1] !== m.y_mm) {
      trail.push([m.x_mm, m.y_mm]);
      if (trail.length > 90) trail.shift();
    }
  }
  const cam = sceneCamera(canvas);
  const P = (p) => cam.project(p);
  const poly = (points) => {
    ctx.beginPath();
    points.forEach((p, i) => (i ? ctx.lineTo(p.x, p.y) : ctx.moveTo(p.x, p.y)));
    ctx.closePath();
  };
  // The ground plane: a checkerboard.
  const n = Math.round((2 * GROUND_HALF_MM) / GROUND_CHECK_MM);
  for (let i = 0; i < n; i++) {
    for (let j = 0; j < n; j++) {
      const x0 = -GROUND_HALF_MM + i * GROUND_CHECK_MM, y0 = -GROUND_HALF_MM + j * GROUND_CHECK_MM;
      const x1 = x0 + GROUND_CHECK_MM, y1 = y0 + GROUND_CHECK_MM;
      poly([P([x0, y0, 0]), P([x1, y0, 0]), P([x1, y1, 0]), P([x0, y1, 0])]);
      ctx.fillStyle = (i + j) % 2 ? "#d9d4c3" : "#e8e3d3";
      ctx.fill();
    }
  }
  // The base's trail on the ground.
  if (trail.length > 1) {
    ctx.strokeStyle = "rgba(230,126,34,0.45)";
    ctx.lineWidth = 2;
    ctx.beginPath();
    trail.forEach(([x, y], i) => { const p = P([x, y, 0]); i ? ctx.lineTo(p.x, p.y) : ctx.moveTo(p.x, p.y); });
    ctx.stroke();
  }
  // Shadows: the spheres' (ellipses on the ground) and the pole's (a line from its base).
  ctx.fillStyle = "rgba(60,50,40,0.28)";
  for (const s of SPHERES) {
    const c = shadowOf(s.centre);
    const along = norm([-LIGHT[0], -LIGHT[1], 0]);
    const across = [-along[1], along[0], 0];
    const stretch = 1 / LIGHT[2];
    const pts = [];
    for (let k = 0; k < 24; k++) {
      const a = (2 * Math.PI * k) / 24;
      pts.push(P(add(c, add(mul(along, s.r * stretch * Math.cos(a)), mul(across, s.r * Math.sin(a))))));
    }
    poly(pts);
    ctx.fill();
  }
  const items = [];
  if (m) {
    const base = [m.x_mm, m.y_mm, 0], top = [m.x_mm, m.y_mm, m.height_mm];
    const b = P(base), t = P(top), sh = P(shadowOf(top));
    ctx.strokeStyle = "rgba(60,50,40,0.45)";
    ctx.lineWidth = 3;
    ctx.beginPath(); ctx.moveTo(b.x, b.y); ctx.lineTo(sh.x, sh.y); ctx.stroke();
    items.push({
      depth: t.z,
      draw() {
        ctx.strokeStyle = "#444";
        ctx.lineWidth = 3;
        ctx.beginPath(); ctx.moveTo(b.x, b.y); ctx.lineTo(t.x, t.y); ctx.stroke();
        ctx.fillStyle = "#555";
        ctx.beginPath(); ctx.ellipse(b.x, b.y, 9, 4, 0, 0, 2 * Math.PI); ctx.fill();
        ctx.fillStyle = "#e67e22";
        ctx.beginPath(); ctx.arc(t.x, t.y, Math.max(4, 3 * t.s), 0, 2 * Math.PI); ctx.fill();
        ctx.strokeStyle = "#7a3d00";
        ctx.lineWidth = 1;
        ctx.stroke();
      },
    });
  }
  const hover = m ? sphereAt([m.x_mm, m.y_mm, m.height_mm]) : null;
  for (const s of SPHERES) {
    const c = P(s.centre);
    const selected = s.name === mouseState.selected;
    items.push({
      depth: c.z,
      draw() {
        const rad = s.r * c.s;
        const g = ctx.createRadialGradient(c.x - rad / 3, c.y - rad / 3, rad / 8, c.x, c.y, rad);
        const k = selected ? 1.25 : s === hover ? 1.1 : 0.9;
        g.addColorStop(0, shade(s.colour, 1.6 * k));
        g.addColorStop(1, shade(s.colour, 0.7 * k));
        ctx.fillStyle = g;
        ctx.beginPath(); ctx.arc(c.x, c.y, rad, 0, 2 * Math.PI); ctx.fill();
        if (selected || s === hover) {
          ctx.strokeStyle = selected ? "#c0392b" : "#555";
          ctx.lineWidth = selected ? 3 : 1.5;
          ctx.stroke();
        }
        ctx.fillStyle = "#333";
        ctx.font = "12px sans-serif";
        ctx.fillText(s.name, c.x + rad + 3, c.y - rad + 4);
      },
    });
  }
  items.sort((p, q) => q.depth - p.depth);
  for (const it of items) it.draw();
  // The selection: a line from the cursor to the selected sphere.
  const sel = SPHERES.find((s) => s.name === mouseState.selected);
  if (m && sel) {
    const a = P([m.x_mm, m.y_mm, m.height_mm]), b = P(sel.centre);
    ctx.strokeStyle = "#c0392b";
    ctx.lineWidth = 2;
    ctx.setLineDash([6, 4]);
    ctx.beginPath(); ctx.moveTo(a.x, a.y); ctx.lineTo(b.x, b.y); ctx.stroke();
    ctx.setLineDash([]);
  }
  // The readings: the pole's height (0..80 mm) and the two buttons.
  const bx = canvas.width - 86, top = 16, bh = 120;
  ctx.strokeStyle = "#bbb";
  ctx.strokeRect(bx, top, 18, bh);
  const h = m ? Math.max(0, Math.min(1, m.height_mm / 80)) : 0;
  ctx.fillStyle = "#e67e22";
  ctx.fillRect(bx, top + bh * (1 - h), 18, bh * h);
  ctx.fillStyle = "#555";
  ctx.font = "11px sans-serif";
  ctx.fillText("height", bx - 8, top + bh + 14);
  const names = ["finger 4", "thumb"];
  names.forEach((name, i) => {
    const on = !!(m && m.buttons && m.buttons[i]);
    const cx = bx + 52, cy = top + 16 + i * 58;
    ctx.fillStyle = on ? "#c0392b" : "#ddd";
    ctx.beginPath(); ctx.arc(cx, cy, 13, 0, 2 * Math.PI); ctx.fill();
    ctx.fillStyle = "#555";
    ctx.fillText(name, cx - 20, cy + 27);
  });
  if (!m) {
    ctx.fillStyle = "#667";
    ctx.font = "14px sans-serif";
    ctx.fillText("no mouse reading", 16, 24);
  }
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
  const word = trackStatus(s);
  document.body.dataset.status = word;
  if (snap.no_signal) {
    status.className = "badge nosignal";
    status.textContent = s ? "NO SIGNAL" : "WAITING";
  } else if (word === "searching") {
    status.className = "badge searching";
    status.textContent = "SEARCHING";
  } else if (word === "lost") {
    status.className = "badge lost";
    status.textContent = "LOST TRACK";
  } else {
    status.className = "badge tracking";
    status.textContent = "TRACKING";
  }
  $("frame").textContent = s
    ? `frame ${s.frame} · ${word} · rms ${Number.isFinite(s.rms_px) ? s.rms_px.toFixed(2) : "–"} px · ` +
      `${s.features_found}/${s.features_expected} features · ${s.iterations} iterations` +
      (snap.hypotheses > 1
        ? ` · ${snap.hypotheses} hypotheses, the best scoring ${Number(snap.best_score).toFixed(3)}`
        : "")
    : "no state yet";
  document.body.dataset.frame = s ? String(s.frame) : "";
  document.title = s ? `digiteyes · frame ${s.frame}` : "digiteyes";

  const l = snap.link;
  const rows = [
    ["states received", l.states],
    ["states/s (last 2 s)", l.states_per_s.toFixed(1)],
    ["lost-track states (searching included)", l.lost_states],
    ["searching states", l.searching_states],
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
