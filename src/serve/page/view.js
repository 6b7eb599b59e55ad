// palpa serve's page: the liver's stress under the trainee's fingers, in plan view.
//
// Everything static (outlines, ROI cells, colour lookup table, palette, extent, training
// domain) comes from /scene.json, computed by the server from the model's files; every frame
// (the hand and the predicted stress of each ROI element, Pa) comes over the WebSocket /ws and
// is shared by every screen. The page draws at the display's frame rate (requestAnimationFrame)
// whenever a frame has arrived, and measures what it does: frames painted per second, and for
// every input message the time from its stamp (the wall-clock time it was made) to the end of
// the first animation frame painted after it arrived ("input to paint").
//
// Frame: x to the patient's left (right of the picture), y cranial (up), metres.
"use strict";

const palpa = (() => {
  const canvas = document.getElementById("view");     // what changes: cells, fingers
  const ctx = canvas.getContext("2d");
  const back = document.getElementById("static");     // what does not: outlines, ticks
  const stage = document.getElementById("stage");
  const el = (id) => document.getElementById(id);
  let scene = null;
  let frame = null;        // newest frame from the server
  let devMap = null;       // newest deviation map
  let dirty = false;       // a frame arrived since the last paint
  let paths = null;        // Path2D of the cells, the liver and the hull, in CSS px
  let tf = { s: 1, ox: 0, oy: 0 };
  let ws = null;
  const pending = [];      // stamps of the frames that arrived since the last paint
  const stats = { t0: performance.now(), painted: 0, rafs: 0, latencies: [], superseded: 0,
    drawMs: 0, drawMaxMs: 0 };
  const recent = [];       // paint times of the last second, for the live figure
  const recentLat = [];    // the last latencies, for the live figure
  let placed = null;       // where the pointer last pressed [m]
  // ?continuous: repaint every animation frame, new data or not (a load test of the page;
  // by default it paints only when a frame has arrived)
  const continuous = new URLSearchParams(location.search).has("continuous");

  const rgb = (c) => `rgb(${c[0]},${c[1]},${c[2]})`;
  const nowEpoch = () => performance.timeOrigin + performance.now();

  // ---- geometry ---------------------------------------------------------------------------
  function fit() {
    const r = canvas.getBoundingClientRect();
    const dpr = window.devicePixelRatio || 1;
    for (const c of [canvas, back]) {
      c.width = Math.round(r.width * dpr);
      c.height = Math.round(r.height * dpr);
    }
    const [lo, hi] = [scene.extent.lo, scene.extent.hi];
    const s = Math.min(r.width / (hi[0] - lo[0]), r.height / (hi[1] - lo[1]));
    tf = {
      s,
      ox: (r.width - s * (hi[0] - lo[0])) / 2 - s * lo[0],
      oy: (r.height + s * (hi[1] - lo[1])) / 2 + s * lo[1],
    };
    drawStatic(dpr, r.width, r.height);
    const ring = (pts) => { const p = new Path2D(); addRing(p, pts); return p; };
    paths = {
      cells: scene.cells.map(ring),
      liver: scene.view ? scene.view.liver.map(ring) : [],
      hull: scene.domain ? ring(scene.domain.hull) : null,
    };
    dirty = true;
  }
  function addRing(p, ring) {
    ring.forEach((q, k) => {
      const [x, y] = px(q);
      if (k === 0) p.moveTo(x, y); else p.lineTo(x, y);
    });
    p.closePath();
  }
  const px = (p) => [tf.ox + tf.s * p[0], tf.oy - tf.s * p[1]];
  const world = (cx, cy) => [(cx - tf.ox) / tf.s, (tf.oy - cy) / tf.s];

  function path(c, ring, close = true) {
    c.beginPath();
    ring.forEach((p, k) => {
      const [x, y] = px(p);
      if (k === 0) c.moveTo(x, y); else c.lineTo(x, y);
    });
    if (close) c.closePath();
  }

  function drawStatic(dpr, w, h) {
    const c = back.getContext("2d");
    c.setTransform(dpr, 0, 0, dpr, 0, 0);
    const pal = scene.palette;
    c.fillStyle = rgb(pal.background);
    c.fillRect(0, 0, w, h);
    const v = scene.view;
    if (v) {
      c.fillStyle = rgb(pal.torso);
      path(c, v.torso); c.fill();
      // a model with a phase input draws the liver where the phase moves it (draw())
      if (!scene.model.takes_phase) {
        c.fillStyle = rgb(pal.liver_fill);
        v.liver.forEach((l) => { path(c, l); c.fill(); });
      }
      c.fillStyle = rgb(pal.rib_fill);
      c.strokeStyle = rgb(pal.rib_line);
      c.lineWidth = 1;
      v.ribs.forEach((r) => { path(c, r); c.fill(); c.stroke(); });
      if (v.model_box) {
        c.setLineDash([2, 4]);
        c.strokeStyle = rgb(pal.model_box);
        path(c, v.model_box); c.stroke();
        c.setLineDash([]);
      }
    }
    // scale ticks every 20 mm along the bottom and left edges
    c.fillStyle = "#555";
    c.strokeStyle = "#555";
    c.font = "11px sans-serif";
    const [lo, hi] = [scene.extent.lo, scene.extent.hi];
    for (let x = Math.ceil(lo[0] / 0.02) * 0.02; x <= hi[0]; x += 0.02) {
      const [cx] = px([x, 0]);
      c.beginPath(); c.moveTo(cx, h); c.lineTo(cx, h - 6); c.stroke();
      c.fillText(`${Math.round(x * 1e3)}`, cx + 2, h - 8);
    }
    c.textAlign = "right";
    for (let y = Math.ceil(lo[1] / 0.02) * 0.02; y <= hi[1]; y += 0.02) {
      const [, cy] = px([0, y]);
      c.beginPath(); c.moveTo(w - 6, cy); c.lineTo(w, cy); c.stroke();
      c.fillText(`${Math.round(y * 1e3)}`, w - 8, cy + 4);
    }
    c.textAlign = "left";
    c.fillText("mm; x to the patient's left, y cranial", 40, 14);
  }

  // ---- drawing ------------------------------------------------------------------------------
  function lutColour(v) {
    const sc = scene.scale;
    const t = Math.min(1, Math.max(0, (v - sc.lo) / (sc.hi - sc.lo)));
    return sc.lut[Math.round(t * (sc.lut.length - 1))];
  }

  function draw() {
    const dpr = window.devicePixelRatio || 1;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const pal = scene.palette;
    // the liver and its ROI move caudally (down the page) with the respiratory phase; the
    // moved liver is translucent, so the ribs of the still background show through, and lies
    // under the deviation overlay
    const shift = frame && frame.liver_shift ? frame.liver_shift * tf.s : 0;
    if (scene.model.takes_phase) {
      ctx.save();
      ctx.translate(0, shift);
      ctx.globalAlpha = 0.6;
      ctx.fillStyle = rgb(pal.liver_fill);
      paths.liver.forEach((l) => ctx.fill(l));
      ctx.restore();
    }
    if (devImage && el("deviation").checked) drawDeviation();
    ctx.save();
    ctx.translate(0, shift);
    if (frame) {
      // cells by rising stress: where elements overlap in plan, the largest shows
      const s = frame.stress;
      const order = s.map((_, i) => i).sort((a, b) => s[a] - s[b]);
      for (const i of order) {
        ctx.fillStyle = lutColour(s[i]);
        ctx.fill(paths.cells[i]);
      }
    }
    ctx.strokeStyle = rgb(pal.liver_line);
    ctx.lineWidth = 2;
    paths.liver.forEach((l) => ctx.stroke(l));
    ctx.restore();
    if (paths.hull) {
      ctx.setLineDash([1, 4]);
      ctx.strokeStyle = rgb(pal.hull);
      ctx.lineWidth = 1.5;
      ctx.stroke(paths.hull);
      ctx.setLineDash([]);
    }
    if (frame) drawFingers(pal);
  }

  function drawFingers(pal) {
    const f = scene.fingers;
    const h = f.spacing_m / 2;
    const rad = (f.diameter_m / 2) * tf.s;
    ctx.strokeStyle = rgb(pal.fingers);
    ctx.lineWidth = 2;
    ctx.setLineDash(frame.lifted ? [4, 4] : []);
    for (const sgn of [-1, 1]) {
      const [cx, cy] = px([frame.x + sgn * h * f.axis[0], frame.y + sgn * h * f.axis[1]]);
      ctx.beginPath(); ctx.arc(cx, cy, rad, 0, 2 * Math.PI); ctx.stroke();
    }
    ctx.setLineDash([]);
    const [cx, cy] = px([frame.x, frame.y]);
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(cx - 5, cy); ctx.lineTo(cx + 5, cy);
    ctx.moveTo(cx, cy - 5); ctx.lineTo(cx, cy + 5);
    ctx.stroke();
  }

  // the deviation map as a small image (one pixel per grid point), scaled up smoothly: purple
  // with opacity sd / prior (clear where the GP knows, opaque where it has no data)
  let devImage = null;
  function buildDeviation() {
    const g = devMap.grid;
    const prior = devMap.prior || 1;
    const img = document.createElement("canvas");
    img.width = g.nx;
    img.height = g.ny;
    const c = img.getContext("2d");
    const data = c.createImageData(g.nx, g.ny);
    for (let j = 0; j < g.ny; j++) {
      for (let i = 0; i < g.nx; i++) {
        const sd = devMap.sd[j * g.nx + i];
        const k = ((g.ny - 1 - j) * g.nx + i) * 4;   // image rows run downwards, y upwards
        data.data[k] = 90; data.data[k + 1] = 0; data.data[k + 2] = 140;
        data.data[k + 3] = sd == null ? 0 : Math.round(Math.min(1, sd / prior) * 0.6 * 255);
      }
    }
    c.putImageData(data, 0, 0);
    devImage = img;
  }

  function drawDeviation() {
    const g = devMap.grid;
    const [x0, y0] = px([g.x0 - g.dx / 2, g.y0 + (g.ny - 0.5) * g.dy]);
    ctx.imageSmoothingEnabled = true;
    ctx.drawImage(devImage, x0, y0, g.nx * g.dx * tf.s, g.ny * g.dy * tf.s);
  }

  let gaugeForce = -1;
  function drawGauge() {
    const f = frame ? frame.force : 0;
    if (Math.abs(f - gaugeForce) < 0.05) return;
    gaugeForce = f;
    const g = el("gauge");
    const c = g.getContext("2d");
    const lim = scene.force_limit_n;
    const [x0, w, top, bot] = [10, 26, 10, g.height - 10];
    const yOf = (f) => bot - (bot - top) * Math.min(1, f / lim);
    c.clearRect(0, 0, g.width, g.height);
    c.fillStyle = "#eee"; c.fillRect(x0, top, w, bot - top);
    const over = scene.domain && f > scene.domain.force_max_n;
    c.fillStyle = over ? "#c80000" : "#2a6fb0";
    c.fillRect(x0, yOf(f), w, bot - yOf(f));
    c.strokeStyle = "#333"; c.lineWidth = 1; c.strokeRect(x0, top, w, bot - top);
    c.fillStyle = "#333"; c.font = "10px sans-serif";
    for (let v = 0; v <= lim + 1e-9; v += lim / 5) {
      const y = yOf(v);
      c.beginPath(); c.moveTo(x0 + w, y); c.lineTo(x0 + w + 4, y); c.stroke();
      c.fillText(v.toFixed(0), x0 + w + 6, y + 3);
    }
    if (scene.domain) {
      const y = yOf(scene.domain.force_max_n);
      c.strokeStyle = "#c80000"; c.lineWidth = 2;
      c.beginPath(); c.moveTo(x0 - 6, y); c.lineTo(x0 + w, y); c.stroke();
    }
  }

  function drawColourBar() {
    const g = el("colourbar");
    const c = g.getContext("2d");
    const sc = scene.scale;
    const [x0, w, top, bot] = [8, 24, 10, g.height - 10];
    for (let y = top; y < bot; y++) {
      const v = sc.hi - (sc.hi - sc.lo) * (y - top) / (bot - top - 1);
      c.fillStyle = lutColour(v);
      c.fillRect(x0, y, w, 1);
    }
    c.strokeStyle = "#333"; c.strokeRect(x0, top, w, bot - top);
    c.fillStyle = "#333"; c.font = "10px sans-serif";
    const marks = [0, 1, 2, 3, 4, 5].map((k) => sc.lo + (sc.hi - sc.lo) * k / 5);
    if (sc.lo < 0) marks.push(0);
    for (const v of marks) {
      const y = top + (bot - top - 1) * (sc.hi - v) / (sc.hi - sc.lo);
      c.beginPath(); c.moveTo(x0 + w, y); c.lineTo(x0 + w + 4, y); c.stroke();
      c.fillText((v / 1e3).toFixed(1), x0 + w + 6, y + 3);
    }
  }

  // the numbers at most 10 times a second (text layout costs more than the picture); the
  // warning as soon as it changes
  let shownAt = 0;
  let shownWarnings = "";
  function showReadout() {
    if (!frame) return;
    const wkey = frame.warnings.map((x) => x.code).join(",");
    const t = performance.now();
    if (t - shownAt < 100 && wkey === shownWarnings) return;
    shownAt = t;
    shownWarnings = wkey;
    drawGauge();
    el("rx").textContent = (frame.x * 1e3).toFixed(1);
    el("ry").textContent = (frame.y * 1e3).toFixed(1);
    el("rf").textContent = frame.force.toFixed(1) + (frame.lifted ? " (lifted)" : "");
    el("rmax").textContent = (frame.max.value / 1e3).toFixed(2);
    el("rsd").textContent = frame.sd == null ? "(MLP: none)" : (frame.sd / 1e3).toFixed(2) + " kPa";
    el("rsrc").textContent = frame.source;
    const w = frame.warnings;
    const box = el("warning");
    box.hidden = w.length === 0;
    box.textContent = w.length ? "Outside what the model was trained on: " + w.map((x) => x.text).join("; ") : "";
    stage.classList.toggle("outside", w.length > 0);
  }

  // ---- the frame loop -----------------------------------------------------------------------
  function loop() {
    stats.rafs++;
    if ((dirty || continuous) && scene && paths) {
      dirty = false;
      const t0 = performance.now();
      draw();
      showReadout();
      const dt = performance.now() - t0;
      stats.drawMs += dt;
      stats.drawMaxMs = Math.max(stats.drawMaxMs, dt);
      const tp = nowEpoch();
      const tn = performance.now();
      for (const st of pending) {
        const l = tp - st;
        stats.latencies.push(l);
        recentLat.push(l);
      }
      stats.superseded += Math.max(0, pending.length - 1);
      pending.length = 0;
      while (recentLat.length > 300) recentLat.shift();
      stats.painted++;
      recent.push(tn);
      while (recent.length && recent[0] < tn - 1000) recent.shift();
    }
    requestAnimationFrame(loop);
  }

  setInterval(() => {
    el("sfps").textContent = recent.length.toString();
    if (recentLat.length >= 20) {
      const s = [...recentLat].sort((a, b) => a - b);
      const q = (p) => s[Math.min(s.length - 1, Math.floor(p * s.length))];
      el("slat").textContent = `p50 ${q(0.5).toFixed(1)} ms, p99 ${q(0.99).toFixed(1)} ms`;
    }
  }, 500);

  // ---- the socket ---------------------------------------------------------------------------
  function connect() {
    ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws`);
    ws.onopen = () => { el("conn").textContent = "live"; el("conn").className = ""; };
    ws.onclose = () => {
      el("conn").textContent = "disconnected: retrying";
      el("conn").className = "off";
      setTimeout(connect, 1000);
    };
    ws.onmessage = (ev) => {
      const m = JSON.parse(ev.data);
      if (m.type === "frame") {
        frame = m;
        pending.push(m.stamp);
        dirty = true;
        placed = [m.x, m.y];
        if (el("deviation").checked) requestDeviation(false);
      } else if (m.type === "deviation_map") {
        devMap = m;
        buildDeviation();
        el("dev-note").textContent = `purple: the GP's deviation at ${m.force.toFixed(0)} N, ` +
          `opaque at its prior ${(m.prior / 1e3).toFixed(2)} kPa (no data there)`;
        dirty = true;
      } else if (m.type === "error") {
        const e = el("error");
        e.hidden = false;
        e.textContent = m.error;
        clearTimeout(e.timer);
        e.timer = setTimeout(() => { e.hidden = true; }, 5000);
      }
    };
  }

  function send(obj) {
    if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(obj));
  }

  function sendPress() {
    if (!placed) return;
    send({ type: "pointer", x: placed[0], y: placed[1], force: +el("force").value, stamp: nowEpoch() });
  }

  let devAsked = { t: 0, force: -1 };
  function requestDeviation(force) {
    const f = frame ? frame.force : 0;
    const t = performance.now();
    if (force || (Math.abs(f - devAsked.force) > 2 && t - devAsked.t > 250)) {
      devAsked = { t, force: f };
      send({ type: "deviation_map", force: f });
    }
  }

  // ---- pointer, wheel and sliders -----------------------------------------------------------
  function setForce(f) {
    const lim = scene.force_limit_n;
    const v = Math.min(lim, Math.max(0, f));
    el("force").value = v;
    el("force-out").textContent = (+el("force").value).toFixed(1);
  }

  function pointerAt(e) {
    const r = canvas.getBoundingClientRect();
    placed = world(e.clientX - r.left, e.clientY - r.top);
    if ((e.pointerType === "pen" || e.pointerType === "touch") && e.pressure > 0) {
      setForce(e.pressure * scene.force_limit_n);
    }
    sendPress();
  }

  canvas.addEventListener("pointerdown", (e) => {
    canvas.setPointerCapture(e.pointerId);
    pointerAt(e);
  });
  canvas.addEventListener("pointermove", (e) => { if (e.buttons) pointerAt(e); });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const px = e.deltaY * (e.deltaMode === 1 ? 33 : e.deltaMode === 2 ? 400 : 1);
    setForce(+el("force").value - px / 100);   // 1 N per 100 px (one notch) of wheel
    sendPress();
  }, { passive: false });
  el("force").addEventListener("input", () => { setForce(+el("force").value); sendPress(); });
  el("phase").addEventListener("input", () => {
    el("phase-out").textContent = (+el("phase").value).toFixed(2);
    send({ type: "phase", value: +el("phase").value });
  });
  el("deviation").addEventListener("change", () => {
    if (el("deviation").checked) requestDeviation(true);
    el("dev-note").hidden = !el("deviation").checked;
    dirty = true;
  });
  let replaying = false;
  el("replay").addEventListener("click", () => {
    replaying = !replaying;
    send({ type: "replay", action: replaying ? "start" : "stop" });
    el("replay").textContent = replaying ? "stop the replay" : "replay the sensor log";
  });

  // ---- start --------------------------------------------------------------------------------
  fetch("/scene.json").then((r) => r.json()).then((s) => {
    scene = s;
    const m = s.model;
    el("model").textContent = `${m.kind} surrogate (${m.target} target), ${m.roi_elements} ROI elements: ${m.path}`;
    el("force").max = s.force_limit_n;
    setForce(20);
    el("phase-note").textContent = m.takes_phase
      ? "the model takes the respiratory phase"
      : "this model takes x, y and force only: it ignores the phase";
    el("deviation").disabled = !m.deviation;
    el("replay").hidden = !s.replay;
    fit();
    drawColourBar();
    window.addEventListener("resize", fit);
    connect();
    requestAnimationFrame(loop);
  });

  // For tests and the curious: the plan-to-page map, the figures, the state.
  return {
    ready: () => scene !== null && ws !== null && ws.readyState === WebSocket.OPEN && frame !== null,
    transform: () => {
      const r = canvas.getBoundingClientRect();
      return { s: tf.s, ox: tf.ox + r.left, oy: tf.oy + r.top, dpr: window.devicePixelRatio || 1 };
    },
    frame: () => frame,
    scene: () => scene,
    resetStats: () => {
      stats.t0 = performance.now(); stats.painted = 0; stats.rafs = 0;
      stats.latencies = []; stats.superseded = 0; stats.drawMs = 0; stats.drawMaxMs = 0;
    },
    stats: () => ({
      seconds: (performance.now() - stats.t0) / 1e3,
      painted: stats.painted,
      rafs: stats.rafs,
      superseded: stats.superseded,
      draw_mean_ms: stats.painted ? stats.drawMs / stats.painted : 0,
      draw_max_ms: stats.drawMaxMs,
      latencies_ms: stats.latencies.slice(),
    }),
  };
})();
window.palpa = palpa;
