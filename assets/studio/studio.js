// The studio's page (raystep serve): every control is a flag of `raystep render`,
// sent as a query to the server's API (see the README, "The studio"). Plain
// JavaScript, no build step. State for tests is kept in data attributes:
// body[data-state] is "rendering", "ready" or "refused" (body[data-query] the
// query of the picture shown); #story[data-state] is "ready" once a pixel's story
// is shown; #ab[data-state] is "ready" once A/B's figures are shown; #frame[data-zoom]
// is the zoom; #drag[data-light] and [data-camera] the positions sent.
"use strict";

const $ = (id) => document.getElementById(id);
const canvas = $("picture");
const frameBox = $("frame");
const stageBoxes = [...document.querySelectorAll("#stages input")];
const bufferSelect = $("buffer");

// The command line's flags the page sets, other than the stages and the buffer.
const METHOD_FIELDS = ["precision", "intersect", "offset", "spp", "max-depth", "engine", "width", "height"];

// This tab's views: a newer request of a view makes the server cancel the older
// one (query key `view`), so a dragged light renders only its latest position.
const tab = Array.from(crypto.getRandomValues(new Uint8Array(6)), (b) => b.toString(16).padStart(2, "0")).join("");
const VIEW = { b: `${tab}-b`, a: `${tab}-a`, diff: `${tab}-d` };

let scene = null; // /api/scene's "scene"
const moves = { light: null, camera: null }; // positions the page moved, or null
let current = null; // the picture: {query, buffer, image, width, height, screen, eye}
let pinned = null; // A: {options, label, buffer, image}
let abFigures = null;
let selected = null; // the pixel whose story is shown, {x, y}
const view = { zoom: 1, x: 0, y: 0, fitted: true };
const requests = {}; // channel -> AbortController of its latest request
const generations = {}; // channel -> number of its latest request

// Start a request on `channel`, aborting the one it supersedes.
function begin(channel) {
  if (requests[channel]) requests[channel].abort();
  requests[channel] = new AbortController();
  generations[channel] = (generations[channel] || 0) + 1;
  const mine = generations[channel];
  return { signal: requests[channel].signal, current: () => generations[channel] === mine };
}

const round = (v) => Number(v.toFixed(4));
const point = (p) => p.map(round).join(",");

// The stage switches as the command line's flags: --stage is the last switch on,
// and --without each switch before it that is off. The server applies the
// command line's rules, and a set it refuses comes back with its reason.
function options() {
  const query = new URLSearchParams();
  let last = -1;
  stageBoxes.forEach((box, i) => {
    if (box.checked) last = i;
  });
  if (last < 0) {
    query.append("stage", "rays");
    query.append("without", "rays");
  } else {
    query.append("stage", stageBoxes[last].value);
    for (const box of stageBoxes.slice(0, last)) {
      if (!box.checked) query.append("without", box.value);
    }
  }
  if ($("tutorial").checked) query.append("tutorial", "");
  const form = $("controls");
  for (const name of METHOD_FIELDS) {
    const value = form.elements[name].value.trim();
    if (value !== "") query.append(name, value);
  }
  for (const name of ["light", "camera"]) {
    if (moves[name]) query.append(name, point(moves[name]));
  }
  return query;
}

function showProblem(element, text) {
  element.textContent = text || "";
  element.hidden = !text;
}

async function errorOf(response) {
  try {
    return (await response.json()).error;
  } catch {
    return `${response.status} ${response.statusText}`;
  }
}

// A PNG's pixels, as they are in the file (no colour conversion).
async function pixelsOf(blob) {
  const bitmap = await createImageBitmap(blob, { colorSpaceConversion: "none", premultiplyAlpha: "none" });
  const scratch = document.createElement("canvas");
  scratch.width = bitmap.width;
  scratch.height = bitmap.height;
  const context = scratch.getContext("2d", { willReadFrequently: true });
  context.drawImage(bitmap, 0, 0);
  bitmap.close();
  return context.getImageData(0, 0, scratch.width, scratch.height);
}

// GET /api/render for `query` on `channel`: {image, response}, or {error}, or
// null if superseded.
async function fetchPicture(channel, query) {
  const request = begin(channel);
  let response;
  try {
    response = await fetch(`/api/render?${query}&view=${VIEW[channel]}`, { signal: request.signal });
  } catch (e) {
    if (e.name === "AbortError" || !request.current()) return null;
    return { error: `the server does not answer: ${e.message}` };
  }
  if (!request.current()) return null;
  if (!response.ok) {
    const error = await errorOf(response);
    return request.current() ? { error } : null;
  }
  const image = await pixelsOf(await response.blob());
  return request.current() ? { image, response } : null;
}

async function render() {
  const query = options();
  query.set("buffer", bufferSelect.value);
  document.body.dataset.state = "rendering";
  $("status").textContent = "rendering…";
  const started = performance.now();
  const got = await fetchPicture("b", query);
  if (!got) return;
  if (got.error) return refused(got.error);
  const { image, response } = got;
  const buffers = (response.headers.get("X-Raystep-Buffers") || "").split(",");
  for (const option of bufferSelect.options) option.disabled = !buffers.includes(option.value);
  const sized = !current || current.width !== image.width || current.height !== image.height;
  const numbers = (header) => (response.headers.get(header) || "").split(",").map(Number);
  current = {
    query: query.toString(),
    buffer: bufferSelect.value,
    image,
    width: image.width,
    height: image.height,
    screen: numbers("X-Raystep-Screen"),
    eye: numbers("X-Raystep-Camera"),
  };
  if (sized && view.fitted) fit();
  draw();
  const ms = Math.round(performance.now() - started);
  const seconds = Number(response.headers.get("X-Raystep-Render-Seconds"));
  $("status").textContent =
    `${response.headers.get("X-Raystep-Size")}, ${bufferSelect.value}: ${ms} ms ` +
    `(the render ${(seconds * 1000).toFixed(1)} ms), scene version ` +
    `${response.headers.get("X-Raystep-Scene-Version")}`;
  showProblem($("refusal"), "");
  document.body.dataset.query = current.query;
  document.body.dataset.sceneVersion = response.headers.get("X-Raystep-Scene-Version");
  document.body.dataset.state = "ready";
  if (pinned) compare();
}

function refused(reason) {
  showProblem($("refusal"), reason);
  $("status").textContent = "refused: the picture is the last one rendered";
  document.body.dataset.state = "refused";
}

// ---- Exposure and false colour: what is drawn from the picture's bytes ----

// A ramp from dark blue through green and yellow to red (stops interpolated in
// straight lines), for values that are not light: depth, counts.
const RAMP = [
  [0.05, 0.03, 0.35],
  [0.0, 0.45, 0.85],
  [0.1, 0.75, 0.45],
  [0.95, 0.85, 0.15],
  [0.8, 0.1, 0.1],
];
function ramp(t) {
  const at = Math.min(Math.max(t, 0), 1) * (RAMP.length - 1);
  const i = Math.min(Math.floor(at), RAMP.length - 2);
  const f = at - i;
  return RAMP[i].map((c, k) => Math.round((c + (RAMP[i + 1][k] - c) * f) * 255));
}
const RAMP_TABLE = Array.from({ length: 256 }, (_, i) => ramp(i / 255));
$("legend-bar").style.background = `linear-gradient(to right, ${RAMP.map((c) => `rgb(${c.map((v) => Math.round(v * 255)).join(",")})`).join(", ")})`;

// |A − B| channel by channel, of two pictures of one size.
function difference(a, b) {
  const out = new ImageData(a.width, a.height);
  for (let i = 0; i < a.data.length; i += 4) {
    out.data[i] = Math.abs(a.data[i] - b.data[i]);
    out.data[i + 1] = Math.abs(a.data[i + 1] - b.data[i + 1]);
    out.data[i + 2] = Math.abs(a.data[i + 2] - b.data[i + 2]);
    out.data[i + 3] = 255;
  }
  return out;
}

// The picture to show: B (the one just rendered), A, or their difference.
function shown() {
  const show = document.querySelector('#ab-show input:checked').value;
  if (!pinned || show === "b" || !pinned.image) return current && current.image;
  if (show === "a") return pinned.image;
  const a = pinned.image;
  const b = current.image;
  if (a.width !== b.width || a.height !== b.height) return b;
  if (!pinned.diff || pinned.diff.of !== b) pinned.diff = { of: b, image: difference(a, b) };
  return pinned.diff.image;
}

function draw() {
  const source = shown();
  if (!source) return;
  const ev = Number($("exposure").value);
  const gain = 2 ** ev;
  const exposed = Array.from({ length: 256 }, (_, v) => Math.min(255, Math.round(v * gain)));
  const falseColour = $("false-colour").checked;
  const out = new ImageData(source.width, source.height);
  const s = source.data;
  const d = out.data;
  for (let i = 0; i < s.length; i += 4) {
    const r = exposed[s[i]];
    const g = exposed[s[i + 1]];
    const b = exposed[s[i + 2]];
    if (falseColour) {
      const c = RAMP_TABLE[Math.round(0.2126 * r + 0.7152 * g + 0.0722 * b)];
      d[i] = c[0];
      d[i + 1] = c[1];
      d[i + 2] = c[2];
    } else {
      d[i] = r;
      d[i + 1] = g;
      d[i + 2] = b;
    }
    d[i + 3] = 255;
  }
  if (canvas.width !== out.width || canvas.height !== out.height) {
    canvas.width = out.width;
    canvas.height = out.height;
  }
  // Kept on the CPU: the page writes it whole each time (and tests read it).
  canvas.getContext("2d", { willReadFrequently: true }).putImageData(out, 0, 0);
  canvas.dataset.drawn = `${document.querySelector('#ab-show input:checked').value}`;
  $("exposure-value").textContent = `${ev > 0 ? "+" : ""}${ev} EV`;
  $("legend").hidden = !falseColour;
  place();
}

// ---- Zoom and pan: the canvas scaled (nearest neighbour) and moved ----

function place() {
  canvas.style.width = `${canvas.width}px`;
  canvas.style.height = `${canvas.height}px`;
  canvas.style.transform = `translate(${view.x}px, ${view.y}px) scale(${view.zoom})`;
  const level = view.zoom >= 1 ? `×${+view.zoom.toFixed(2)}` : `×${view.zoom.toFixed(3)}`;
  $("zoom-level").textContent = level;
  frameBox.dataset.zoom = String(view.zoom);
  placeMarker();
}

// As large as the frame allows: a whole number of times (each pixel a sharp
// square), or shrunk to fit.
function fit() {
  if (!current) return;
  const room = { w: frameBox.clientWidth, h: frameBox.clientHeight };
  const scale = Math.min(room.w / current.width, room.h / current.height);
  view.zoom = scale >= 1 ? Math.floor(scale) : scale;
  view.x = Math.round((room.w - current.width * view.zoom) / 2);
  view.y = Math.round((room.h - current.height * view.zoom) / 2);
  view.fitted = true;
  place();
}

// Zoom by `factor` keeping the point (cx, cy) of the frame where it is.
function zoomAt(factor, cx, cy) {
  const zoom = Math.min(Math.max(view.zoom * factor, 1 / 16), 256);
  view.x = cx - ((cx - view.x) * zoom) / view.zoom;
  view.y = cy - ((cy - view.y) * zoom) / view.zoom;
  view.zoom = zoom;
  view.fitted = false;
  place();
}

// Where the frame's inside (the canvas's origin, within its border) is on the screen.
function origin() {
  const box = frameBox.getBoundingClientRect();
  return { left: box.left + frameBox.clientLeft, top: box.top + frameBox.clientTop };
}

// The pixel under a point of the screen, or null outside the picture.
function pixelAt(clientX, clientY) {
  if (!current) return null;
  const box = origin();
  const x = Math.floor((clientX - box.left - view.x) / view.zoom);
  const y = Math.floor((clientY - box.top - view.y) / view.zoom);
  if (x < 0 || y < 0 || x >= current.width || y >= current.height) return null;
  return { x, y };
}

function placeMarker() {
  const marker = $("marker");
  if (!selected || !current) {
    marker.hidden = true;
    return;
  }
  const size = Math.max(view.zoom, 6);
  Object.assign(marker.style, {
    left: `${view.x + (selected.x + 0.5) * view.zoom - size / 2}px`,
    top: `${view.y + (selected.y + 0.5) * view.zoom - size / 2}px`,
    width: `${size}px`,
    height: `${size}px`,
  });
  marker.hidden = false;
}

// ---- Dragging the light or the camera in the screen's plane ----

function showPositions() {
  const describe = (name) => {
    const p = moves[name] || (scene && (name === "light" ? scene.light.position : scene.camera));
    return p ? `(${p.map((v) => round(v)).join(", ")})${moves[name] ? " moved" : ""}` : "—";
  };
  $("light-position").textContent = describe("light");
  $("camera-position").textContent = describe("camera");
  $("drag").dataset.light = moves.light ? point(moves.light) : "";
  $("drag").dataset.camera = moves.camera ? point(moves.camera) : "";
  const query = new URLSearchParams();
  for (const name of ["light", "camera"]) if (moves[name]) query.set(name, point(moves[name]));
  $("save-as").href = `/api/scene.toml${query.size ? `?${query}` : ""}`;
}

// Where a drag of (dx, dy) pixels of the picture (right and down) takes the
// light or the camera from `start`: parallel to the screen (x and y; z kept), by
// an exact amount read from the grid the picture was rendered on. The render's
// headers say which: X-Raystep-Screen (the rectangle at z = 0, left, right, top,
// bottom) and X-Raystep-Camera (the eye). camera.rs's pixels look at
// linspace(left, right, width) across and linspace(top, bottom, height) down, so
// neighbouring pixels' points on the screen are `across` and `down` apart.
// - The camera moves by the pixels dragged times those steps: the eye slides as
//   far as the pointer slid over the screen, and the ray through the pixel now
//   under the pointer is the ray that was under it at the start, moved without
//   turning. The screen stays (raystep's screen does not move with the eye), so
//   what lies on it stays put, what lies far beyond it follows the pointer, and
//   what lies between slides by the parallax of a head moving before a window.
// - The light moves so that its image (where the line from the eye through it
//   meets the screen) follows the pointer exactly: a point at depth z is seen at
//   eye + (point - eye) * e / (e - z), e the eye's z, so one step on the screen is
//   (e - z) / e steps in the light's plane. A light behind the eye (that ratio
//   below 0) has no image in the picture; it moves by the ratio's size all the
//   same, so that seen from the eye it turns by as much as a light in front at
//   its distance would. Level with the eye (ratio 0) it would not move: it moves
//   by the screen's steps then.
// tests/serve.rs checks both against camera.rs's projection, pixel for pixel.
function moveBy(what, start, dx, dy) {
  const [left, right, top, bottom] = current.screen;
  const across = current.width > 1 ? (right - left) / (current.width - 1) : 0;
  const down = current.height > 1 ? (top - bottom) / (current.height - 1) : 0;
  let ratio = 1;
  if (what === "light") {
    const e = current.eye[2];
    ratio = Math.abs((e - start[2]) / e) || 1;
  }
  return [start[0] + dx * across * ratio, start[1] - dy * down * ratio, start[2]];
}

// ---- Pointer: drag pans or moves, a click picks a pixel ----

let press = null;
let moveTimer = null;
frameBox.addEventListener("pointerdown", (event) => {
  if (event.button !== 0 || !current) return;
  const mode = document.querySelector('#drag input[name="drag"]:checked').value;
  const start = mode === "pan" ? null : [...(moves[mode] || (mode === "light" ? scene.light.position : scene.camera))];
  press = { x: event.clientX, y: event.clientY, mode, start, view: { ...view }, dragging: false };
  frameBox.setPointerCapture(event.pointerId);
});
frameBox.addEventListener("pointermove", (event) => {
  hover(event);
  if (!press) return;
  const dx = event.clientX - press.x;
  const dy = event.clientY - press.y;
  if (!press.dragging && Math.hypot(dx, dy) < 4) return;
  press.dragging = true;
  frameBox.classList.add("dragging");
  if (press.mode === "pan") {
    view.x = press.view.x + dx;
    view.y = press.view.y + dy;
    view.fitted = false;
    place();
    return;
  }
  moves[press.mode] = moveBy(press.mode, press.start, dx / view.zoom, dy / view.zoom);
  showPositions();
  clearTimeout(moveTimer);
  moveTimer = setTimeout(render, 30);
});
function release(event) {
  if (!press) return;
  const was = press;
  press = null;
  frameBox.classList.remove("dragging");
  if (!was.dragging) {
    const pixel = pixelAt(event.clientX, event.clientY);
    if (pixel) {
      selected = pixel;
      placeMarker();
      explainPixel();
    }
  } else if (was.mode !== "pan") {
    clearTimeout(moveTimer);
    changed();
  }
}
frameBox.addEventListener("pointerup", release);
frameBox.addEventListener("pointercancel", () => {
  press = null;
  frameBox.classList.remove("dragging");
});
frameBox.addEventListener(
  "wheel",
  (event) => {
    event.preventDefault();
    const box = origin();
    zoomAt(event.deltaY < 0 ? 2 : 0.5, event.clientX - box.left, event.clientY - box.top);
  },
  { passive: false },
);

// The pixel under the pointer and the bytes drawn there.
function hover(event) {
  const pixel = pixelAt(event.clientX, event.clientY);
  const source = shown();
  if (!pixel || !source) {
    $("hover").textContent = "";
    return;
  }
  const i = (pixel.y * source.width + pixel.x) * 4;
  const bytes = [source.data[i], source.data[i + 1], source.data[i + 2]];
  $("hover").textContent = `pixel (${pixel.x}, ${pixel.y}): bytes ${bytes.join(", ")} of the picture shown`;
}

function zoomButton(factor) {
  zoomAt(factor, frameBox.clientWidth / 2, frameBox.clientHeight / 2);
}
$("zoom-in").addEventListener("click", () => zoomButton(2));
$("zoom-out").addEventListener("click", () => zoomButton(0.5));
$("zoom-fit").addEventListener("click", fit);
$("zoom-one").addEventListener("click", () => zoomButton(1 / view.zoom));
$("exposure").addEventListener("input", draw);
$("false-colour").addEventListener("change", draw);
$("reset-moves").addEventListener("click", () => {
  moves.light = null;
  moves.camera = null;
  showPositions();
  changed();
});

// ---- A/B: pin the settings as A, compare B with it ----

function setShow(value) {
  for (const input of document.querySelectorAll("#ab-show input")) {
    input.disabled = !pinned;
    input.checked = input.value === value;
  }
}

$("pin").addEventListener("click", () => {
  if (!current) return;
  const optionsNow = new URLSearchParams(current.query);
  optionsNow.delete("buffer");
  pinned = { options: optionsNow, buffer: current.buffer, image: current.image };
  $("ab-pinned").textContent = `A: ${optionsNow.toString() || "(the defaults)"}`;
  $("unpin").disabled = false;
  setShow("b");
  compare();
});
$("unpin").addEventListener("click", () => {
  pinned = null;
  abFigures = null;
  $("unpin").disabled = true;
  $("ab-pinned").textContent = "";
  $("ab-figures").textContent = "";
  delete $("ab").dataset.state;
  setShow("b");
  draw();
});
for (const input of document.querySelectorAll("#ab-show input")) input.addEventListener("change", draw);

// A's picture of the buffer shown, and `raystep diff`'s figures of the two
// renders' beauty (computed by the server with diff's own code).
async function compare() {
  if (!pinned || !current) return;
  const b = new URLSearchParams(current.query);
  b.delete("buffer");
  $("ab").dataset.state = "comparing";
  if (pinned.buffer !== current.buffer || !pinned.image) {
    const query = new URLSearchParams(pinned.options);
    query.set("buffer", current.buffer);
    const got = await fetchPicture("a", query);
    if (!got) return;
    pinned.buffer = current.buffer;
    pinned.image = got.image || null;
    pinned.diff = null;
    if (got.error) $("ab-figures").textContent = `A: ${got.error}`;
  }
  const request = begin("diff");
  const query = new URLSearchParams({ a: pinned.options.toString(), b: b.toString(), view: VIEW.diff });
  let response;
  try {
    response = await fetch(`/api/diff?${query}`, { signal: request.signal });
  } catch (e) {
    if (e.name === "AbortError" || !request.current()) return;
    $("ab-figures").textContent = `the server does not answer: ${e.message}`;
    return;
  }
  if (!request.current()) return;
  if (!response.ok) {
    const reason = await errorOf(response);
    if (!request.current()) return;
    abFigures = null;
    $("ab-figures").textContent = reason;
    $("ab").dataset.state = "refused";
    draw();
    return;
  }
  const figures = await response.json();
  if (!request.current()) return;
  abFigures = figures;
  const percent = (100 * figures.over_one_step) / figures.pixels;
  $("ab-figures").textContent =
    `beauty, as raystep diff compares it: ${figures.over_one_step} of ${figures.pixels} pixels ` +
    `differ by more than 1/255 (${percent.toFixed(2)} %); largest difference ` +
    `${figures.largest === null ? "∞" : figures.largest.toFixed(4)} (row ${figures.largest_at.row}, ` +
    `column ${figures.largest_at.column}); RMSE ${figures.rmse.toFixed(6)}`;
  $("ab").dataset.figures = JSON.stringify(figures);
  $("ab").dataset.a = pinned.options.toString();
  $("ab").dataset.b = b.toString();
  $("ab").dataset.state = "ready";
  draw();
}

// ---- The pixel's story ----

async function explainPixel() {
  if (!selected) return;
  const request = begin("pixel");
  const query = options();
  query.set("x", selected.x);
  query.set("y", selected.y);
  $("story").dataset.state = "loading";
  let response;
  try {
    response = await fetch(`/api/pixel?${query}`, { signal: request.signal });
  } catch (e) {
    if (e.name === "AbortError" || !request.current()) return;
    $("story-text").replaceChildren(paragraph(`the server does not answer: ${e.message}`, "problem"));
    return;
  }
  if (!request.current()) return;
  if (!response.ok) {
    const reason = await errorOf(response);
    if (!request.current()) return;
    $("story-text").replaceChildren(paragraph(reason, "problem"));
    $("story-buffers").replaceChildren();
    $("story-json-box").hidden = true;
    $("story").dataset.state = "refused";
    return;
  }
  const text = await response.text();
  if (!request.current()) return;
  const story = JSON.parse(text);
  $("story-json").textContent = text;
  $("story-json-box").hidden = false;
  $("story-buffers").replaceChildren(...buffersOf(story));
  $("story-text").replaceChildren(...tell(story));
  $("story-hint").hidden = true;
  $("story").dataset.x = story.x;
  $("story").dataset.y = story.y;
  $("story").dataset.state = "ready";
}

// Numbers and vectors as the story shows them.
const num = (v) => (v === null || v === undefined ? "—" : Number.isInteger(v) ? String(v) : Number(v).toPrecision(6));
const vec = (v) => (v ? `(${v.map(num).join(", ")})` : "—");
const value = (v) =>
  v === null || v === undefined ? "—" : Array.isArray(v) ? vec(v) : typeof v === "object" ? JSON.stringify(v) : num(v);

function element(tag, text, className) {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (className) e.className = className;
  return e;
}
const paragraph = (text, className) => element("p", text, className);

function table(rows) {
  const t = element("table");
  for (const [name, v] of rows) {
    const tr = element("tr");
    tr.append(element("th", name), element("td", v));
    t.append(tr);
  }
  return t;
}

function swatch(colour) {
  const s = element("span", undefined, "swatch");
  const byte = (c) => Math.round(Math.min(Math.max(c, 0), 1) * 255);
  s.style.background = `rgb(${colour.map(byte).join(",")})`;
  return s;
}

// The values of every buffer at the pixel: the story's own `buffers` if it
// has them (each shown as it comes), else read from its fields.
function buffersOf(story) {
  const rows = [];
  if (story.buffers && typeof story.buffers === "object") {
    for (const [name, v] of Object.entries(story.buffers)) rows.push([name, value(v)]);
  } else {
    const hit = story.segments[0] && story.segments[0].hit;
    const shading = hit && hit.shading;
    rows.push(["beauty", vec(story.colour)]);
    rows.push(["direction", vec(story.primary.direction)]);
    rows.push(["depth", story.depth === null ? "∞ (miss)" : num(story.depth)]);
    if (hit) {
      rows.push(["normal", vec(hit.normal)]);
      rows.push(["shadow", hit.lit ? "1 (lit)" : "0 (in shadow)"]);
      rows.push(["object", num(hit.object)]);
    } else {
      rows.push(["shadow", "−1 (missed)"], ["object", "−1 (missed)"]);
    }
    if (shading) {
      rows.push(["ambient", vec(shading.ambient)], ["diffuse", vec(shading.diffuse)], ["specular", vec(shading.specular)]);
    }
    rows.push(["bounces", num(story.rays[2])]);
    rows.push(["rays", num(story.rays.reduce((a, b) => a + b, 0))]);
  }
  const box = element("div");
  box.append(element("h3", "Buffers at this pixel"), table(rows));
  return [box];
}

// The story of a pixel, in the words of `raystep explain` (every number from the JSON).
function tell(story) {
  const parts = [];
  const head = element("p");
  head.append(`Pixel (${story.x}, ${story.y}): `, swatch(story.colour), ` ${vec(story.colour)}`);
  parts.push(head);
  parts.push(
    table([
      ["stages", story.stages],
      ["rules", story.rules],
      ["screen point", vec(story.screen_point)],
      ["primary ray", `from ${vec(story.primary.origin)} along ${vec(story.primary.direction)}`],
      ["depth", story.depth === null ? "∞ (miss)" : num(story.depth)],
      ["unclipped", vec(story.unclipped)],
      ["rays", `${story.rays[0]} primary, ${story.rays[1]} shadow, ${story.rays[2]} reflection`],
      ["end", story.end],
    ]),
  );
  if (story.samples) {
    parts.push(paragraph(`${story.samples.spp} samples, mean ${vec(story.samples.colour)}: the pixel.`));
  }
  for (const segment of story.segments) {
    const box = element("div", undefined, "segment");
    box.append(element("h3", `Segment ${segment.index} (weight ${num(segment.weight)})`));
    box.append(paragraph(`ray from ${vec(segment.ray.origin)} along ${vec(segment.ray.direction)}`));
    const tests = element("ul");
    for (const test of segment.tests) {
      tests.append(element("li", `object ${test.object}, ${test.what}: ${test.verdict}`, "verdict"));
    }
    for (const unlisted of segment.unlisted) {
      tests.append(element("li", `${unlisted.count} other object${unlisted.count === 1 ? "" : "s"}: ${unlisted.verdict}`, "verdict"));
    }
    box.append(tests);
    const hit = segment.hit;
    if (hit) {
      const rows = [
        ["hit", `object ${hit.object} at t = ${num(hit.t)}`],
        ["point", vec(hit.point)],
        ["normal", vec(hit.normal)],
        ["shifted", `${vec(hit.shifted)} (offset ${num(hit.offset)})`],
        ["lit", hit.lit ? "yes" : "no, in shadow"],
      ];
      if (hit.shadow) {
        const blocker = hit.shadow.blocker;
        rows.push([
          "shadow ray",
          `light at ${num(hit.shadow.light_distance)}; ` +
            (blocker ? `blocked by object ${blocker[0]} at ${num(blocker[1])}` : "nothing in between"),
        ]);
      }
      if (hit.own_shadow !== null && hit.own_shadow !== undefined) {
        rows.push([
          "shadow ray",
          `none: the light is below this sphere's horizon (N·L = ${num(hit.own_shadow)}), so the sphere shadows the point`,
        ]);
      }
      if (hit.shading) {
        const s = hit.shading;
        rows.push(["L·N, N·H", `${num(s.l_dot_n)}, ${num(s.n_dot_h)} (exponent ${num(s.exponent)})`]);
        rows.push(["ambient", vec(s.ambient)], ["diffuse", vec(s.diffuse)], ["specular", vec(s.specular)]);
      }
      rows.push(["adds", hit.illumination ? vec(hit.illumination) : "nothing (in shadow)"]);
      rows.push(["sum so far", vec(hit.sum)]);
      box.append(table(rows));
    } else {
      box.append(paragraph("no hit: the ray leaves the scene"));
    }
    parts.push(box);
  }
  return parts;
}

async function loadScene() {
  const response = await fetch("/api/scene?objects=none");
  const answer = await response.json();
  scene = answer.scene;
  $("scene-name").textContent = answer.file;
  $("scene-version").textContent = `(version ${answer.version})`;
  document.body.dataset.version = answer.version;
  showProblem($("scene-error"), answer.error ? `${answer.error}\n(the picture is of the last scene that loaded)` : "");
  const form = $("controls");
  form.elements.width.placeholder = scene.width;
  form.elements.height.placeholder = scene.height;
  showPositions();
}

function changed() {
  render();
  explainPixel();
}

let typing = null;
$("controls").addEventListener("change", changed);
$("controls").addEventListener("input", (event) => {
  if (event.target.tagName !== "INPUT" || event.target.type === "checkbox") return;
  clearTimeout(typing);
  typing = setTimeout(changed, 300);
});
for (const form of ["controls", "looks"]) $(form).addEventListener("submit", (event) => event.preventDefault());
window.addEventListener("resize", () => {
  if (view.fitted) fit();
});

const events = new EventSource("/api/events");
events.onmessage = async (event) => {
  const change = JSON.parse(event.data);
  await loadScene();
  if (!change.error) changed();
};

loadScene().then(render);
