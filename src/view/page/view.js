// pathlab view: polls /api/state a few times a second, fetches each slot's newest image as
// float32 RGB, and draws the chosen one (A, B, the reference or the error image) tone-mapped on a
// canvas; the value under the cursor is the float the server sent, not the tone-mapped one.
"use strict";

const $ = (id) => document.getElementById(id);
const view = {
  state: null,
  images: { a: null, b: null, reference: null },  // {width, height, data: Float32Array, frame, render}
  zoom: 1,
  cursor: null,  // [x, y] in pixels
  busy: false,
};

function message(text) { $("message").textContent = text || ""; }

async function getJSON(url) {
  const r = await fetch(url, { cache: "no-store" });
  if (!r.ok) throw new Error(`${url}: ${r.status}`);
  return r.json();
}

async function post(url, body) {
  const r = await fetch(url, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
  const j = await r.json();
  if (!r.ok) throw new Error(j.error || `${url}: ${r.status}`);
  return j;
}

async function fetchImage(url) {
  const r = await fetch(url, { cache: "no-store" });
  if (!r.ok) return null;
  const width = +r.headers.get("X-Width"), height = +r.headers.get("X-Height");
  const data = new Float32Array(await r.arrayBuffer());
  if (data.length !== width * height * 3) return null;
  return { width, height, data, frame: +r.headers.get("X-Frame") };
}

function fillSelects(state) {
  for (const slot of ["a", "b"]) {
    const sel = $(`algorithm-${slot}`);
    if (sel.options.length === 0) {
      for (const a of state.algorithms) {
        const o = new Option(a.name, a.name);
        if (a.refusal) { o.disabled = true; o.title = a.refusal; }
        sel.add(o);
      }
      const samp = $(`sampler-${slot}`);
      for (const s of state.samplers) samp.add(new Option(s, s));
    }
  }
}

function slotText(s) {
  if (!s.active) return "not running";
  const rate = s.samples_per_second > 0 ? ` · ${(s.samples_per_second / 1e6).toFixed(2)} Msamples/s` : "";
  const err = s.error ? ` · ${s.error}` : "";
  return `${s.algorithm} · ${s.sampler} · ${s.spp} spp · ${s.seconds.toFixed(1)} s${rate} · ${s.status}${err}`;
}

async function poll() {
  if (view.busy) return;
  view.busy = true;
  try {
    const state = await getJSON("/api/state");
    const first = view.state === null;
    view.state = state;
    if (first) {
      fillSelects(state);
      $("scene").textContent = state.scene;
      $("size").textContent = `${state.width}×${state.height}`;
      $("algorithm-a").value = state.slots[0].algorithm;
      $("sampler-a").value = state.slots[0].sampler;
      $("algorithm-b").value = state.slots[1].active ? state.slots[1].algorithm : state.slots[0].algorithm;
      if (state.slots[1].active) $("sampler-b").value = state.slots[1].sampler;
      $("rmse-against").textContent = state.reference ? `the reference (${state.reference})` : "each other (A − B)";
      if (state.reference) view.images.reference = await fetchImage("/api/reference");
    }
    let changed = false;
    for (const [i, slot] of [[0, "a"], [1, "b"]]) {
      const s = state.slots[i];
      $(`status-${slot}`).textContent = slotText(s);
      $(`status-${slot}`).dataset.algorithm = s.algorithm;
      $(`status-${slot}`).dataset.render = s.render;
      $(`status-${slot}`).dataset.frame = s.frame;
      $(`status-${slot}`).dataset.status = s.status;
      const have = view.images[slot];
      if (s.frame > 0 && (!have || have.frame !== s.frame || have.render !== s.render)) {
        const img = await fetchImage(`/api/frame/${slot}`);
        if (img) { img.render = s.render; view.images[slot] = img; changed = true; }
      }
      if (!s.active && have) { view.images[slot] = null; changed = true; }
    }
    if (changed || first) draw();
    plot();
  } catch (e) {
    message(`lost the server: ${e.message}`);
  } finally {
    view.busy = false;
  }
}

// The image shown: its floats (RGB) and whether it is an error image.
function shown() {
  const mode = $("show").value;
  const a = view.images.a;
  if (mode === "error") {
    const other = view.images.reference || view.images.b;
    if (!a || !other || other.width !== a.width || other.height !== a.height) return null;
    const data = new Float32Array(a.data.length);
    for (let i = 0; i < data.length; ++i) data[i] = Math.abs(a.data[i] - other.data[i]);
    return { width: a.width, height: a.height, data, error: true };
  }
  return view.images[mode] || null;
}

// A false-colour ramp (dark blue, blue, cyan, green, yellow, red) over t in [0, 1].
const RAMP = [[0.05, 0.03, 0.2], [0.1, 0.2, 0.8], [0.1, 0.7, 0.9], [0.2, 0.8, 0.3], [0.95, 0.85, 0.2], [0.85, 0.15, 0.1]];
function ramp(t) {
  t = Math.min(1, Math.max(0, t)) * (RAMP.length - 1);
  const i = Math.min(RAMP.length - 2, Math.floor(t)), f = t - i;
  return RAMP[i].map((c, k) => c + (RAMP[i + 1][k] - c) * f);
}

function srgb(v) {
  v = Math.min(1, Math.max(0, v));
  return v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
}

function draw() {
  const img = shown();
  const canvas = $("image");
  const what = $("show").value;
  $("note").textContent = img ? "" : what === "error" ? "no error image: it needs A and a reference or B" : `no image of ${what} yet`;
  if (!img) {
    canvas.getContext("2d").clearRect(0, 0, canvas.width, canvas.height);
    canvas.dataset.frame = 0;
    return;
  }
  if (canvas.width !== img.width || canvas.height !== img.height) {
    canvas.width = img.width;
    canvas.height = img.height;
  }
  canvas.style.width = `${img.width * view.zoom}px`;
  canvas.style.height = `${img.height * view.zoom}px`;
  const scale = Math.pow(2, +$("exposure").value);
  const falsecolour = $("tonemap").value === "falsecolour" || img.error;
  const ctx = canvas.getContext("2d");
  const out = ctx.createImageData(img.width, img.height);
  const n = img.width * img.height;
  for (let p = 0; p < n; ++p) {
    const r = img.data[3 * p], g = img.data[3 * p + 1], b = img.data[3 * p + 2];
    let rgb;
    if (falsecolour) {
      // log2 of the luminance (the error's mean over channels) after exposure, from 2^-10 to 2^2.
      const y = img.error ? (r + g + b) / 3 : 0.2126 * r + 0.7152 * g + 0.0722 * b;
      rgb = y > 0 ? ramp((Math.log2(y * scale) + 10) / 12) : [0, 0, 0];
    } else {
      rgb = [srgb(r * scale), srgb(g * scale), srgb(b * scale)];
    }
    out.data[4 * p] = Math.round(255 * rgb[0]);
    out.data[4 * p + 1] = Math.round(255 * rgb[1]);
    out.data[4 * p + 2] = Math.round(255 * rgb[2]);
    out.data[4 * p + 3] = 255;
  }
  ctx.putImageData(out, 0, 0);
  canvas.dataset.frame = img.frame || 0;  // which image is drawn (for tests and scripts)
  readout();
}

// The value under the cursor, of the image shown.
function readout() {
  const el = $("pixel");
  const img = shown();
  if (!view.cursor || !img) return;
  const [x, y] = view.cursor;
  if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
  const i = 3 * (y * img.width + x);
  const v = [img.data[i], img.data[i + 1], img.data[i + 2]];
  el.dataset.x = x;
  el.dataset.y = y;
  el.dataset.rgb = v.join(" ");
  el.textContent = `(${x}, ${y}) ${$("show").value}: ${v.map((c) => c.toPrecision(6)).join("  ")}`;
}

function plot() {
  const canvas = $("rmse"), ctx = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height, pad = 34;
  ctx.clearRect(0, 0, W, H);
  if (!view.state) return;
  const curves = [[view.state.slots[0].rmse, "#8ab4f8"], [view.state.slots[1].rmse, "#fdd663"]];
  const pts = curves.flatMap(([c]) => c).filter(([t, e]) => t > 0 && e > 0);
  ctx.strokeStyle = "#666";
  ctx.strokeRect(pad, 4, W - pad - 4, H - pad - 4);
  if (pts.length < 1) return;
  const lt = pts.map(([t]) => Math.log10(t)), le = pts.map(([, e]) => Math.log10(e));
  const t0 = Math.floor(Math.min(...lt)), t1 = Math.max(Math.ceil(Math.max(...lt)), t0 + 1);
  const e0 = Math.floor(Math.min(...le)), e1 = Math.max(Math.ceil(Math.max(...le)), e0 + 1);
  const X = (t) => pad + (Math.log10(t) - t0) / (t1 - t0) * (W - pad - 4);
  const Y = (e) => H - pad - (Math.log10(e) - e0) / (e1 - e0) * (H - pad - 8);
  ctx.fillStyle = "#aaa";
  ctx.font = "10px sans-serif";
  for (let k = t0; k <= t1; ++k) ctx.fillText(`1e${k}`, Math.min(X(10 ** k) - 8, W - 26), H - pad + 14);
  for (let k = e0; k <= e1; ++k) ctx.fillText(`1e${k}`, 2, Y(10 ** k) + 3);
  for (const [curve, colour] of curves) {
    ctx.strokeStyle = colour;
    ctx.beginPath();
    let started = false;
    for (const [t, e] of curve) {
      if (!(t > 0 && e > 0)) continue;
      if (started) ctx.lineTo(X(t), Y(e)); else ctx.moveTo(X(t), Y(e));
      started = true;
    }
    ctx.stroke();
    // The newest point as a dot (a curve of one point is no line).
    const last = curve.filter(([t, e]) => t > 0 && e > 0).pop();
    if (last) {
      ctx.fillStyle = colour;
      ctx.fillRect(X(last[0]) - 2, Y(last[1]) - 2, 4, 4);
    }
  }
}

async function restart(slot) {
  message("");
  try {
    await post("/api/render", { slot, algorithm: $(`algorithm-${slot}`).value, sampler: $(`sampler-${slot}`).value });
  } catch (e) {
    message(e.message);
  }
}

function setZoom(z) {
  view.zoom = Math.min(64, Math.max(1, z));
  $("zoom-value").textContent = view.zoom;
  draw();
}

$("restart-a").addEventListener("click", () => restart("a"));
$("restart-b").addEventListener("click", () => restart("b"));
$("stop-b").addEventListener("click", () => post("/api/stop", { slot: "b" }).catch((e) => message(e.message)));
for (const id of ["show", "tonemap"]) $(id).addEventListener("change", draw);
$("exposure").addEventListener("input", () => {
  $("exposure-value").textContent = (+$("exposure").value).toFixed(1);
  draw();
});
$("zoom-in").addEventListener("click", () => setZoom(view.zoom * 2));
$("zoom-out").addEventListener("click", () => setZoom(view.zoom / 2));
$("image").addEventListener("wheel", (e) => {
  e.preventDefault();
  setZoom(e.deltaY < 0 ? view.zoom * 2 : view.zoom / 2);
});
$("image").addEventListener("mousemove", (e) => {
  const rect = $("image").getBoundingClientRect();
  view.cursor = [Math.floor((e.clientX - rect.left) / view.zoom), Math.floor((e.clientY - rect.top) / view.zoom)];
  readout();
});

poll();
setInterval(poll, 200);
