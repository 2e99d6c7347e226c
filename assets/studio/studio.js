// The studio's page (raystep serve): every control is a flag of `raystep render`,
// sent as a query to the server's API (see the README, "The studio"). Plain
// JavaScript, no build step. State for tests is kept in data attributes:
// body[data-state] is "rendering", "ready" or "refused"; #story[data-state] is
// "ready" once a pixel's story is shown.
"use strict";

const $ = (id) => document.getElementById(id);
const picture = $("picture");
const stageBoxes = [...document.querySelectorAll("#stages input")];
const bufferSelect = $("buffer");

// The command line's flags the page sets, other than the stages and the buffer.
const METHOD_FIELDS = ["precision", "intersect", "offset", "spp", "max-depth", "engine", "width", "height"];

let generation = 0; // the newest render asked for; older answers are dropped
let inFlight = null; // its AbortController
let selected = null; // the pixel whose story is shown, {x, y}
let storyGeneration = 0;
let objectUrl = null;

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

async function render() {
  const mine = ++generation;
  if (inFlight) inFlight.abort();
  inFlight = new AbortController();
  const query = options();
  query.set("buffer", bufferSelect.value);
  document.body.dataset.state = "rendering";
  $("status").textContent = "rendering…";
  const started = performance.now();
  let response;
  try {
    response = await fetch(`/api/render?${query}`, { signal: inFlight.signal });
  } catch (e) {
    if (e.name === "AbortError") return;
    if (mine === generation) refused(`the server does not answer: ${e.message}`);
    return;
  }
  if (mine !== generation) return;
  if (!response.ok) {
    const reason = await errorOf(response);
    if (mine === generation) refused(reason);
    return;
  }
  const blob = await response.blob();
  if (mine !== generation) return;
  const buffers = (response.headers.get("X-Raystep-Buffers") || "").split(",");
  for (const option of bufferSelect.options) option.disabled = !buffers.includes(option.value);
  const url = URL.createObjectURL(blob);
  picture.onload = () => {
    if (objectUrl) URL.revokeObjectURL(objectUrl);
    objectUrl = url;
    fit();
    const ms = Math.round(performance.now() - started);
    const seconds = Number(response.headers.get("X-Raystep-Render-Seconds"));
    $("status").textContent =
      `${response.headers.get("X-Raystep-Size")}, ${bufferSelect.value}: ${ms} ms ` +
      `(the render ${(seconds * 1000).toFixed(1)} ms), scene version ` +
      `${response.headers.get("X-Raystep-Scene-Version")}`;
    showProblem($("refusal"), "");
    document.body.dataset.query = query.toString();
    document.body.dataset.sceneVersion = response.headers.get("X-Raystep-Scene-Version");
    document.body.dataset.state = "ready";
  };
  picture.src = url;
}

function refused(reason) {
  showProblem($("refusal"), reason);
  $("status").textContent = "refused: the picture is the last one rendered";
  document.body.dataset.state = "refused";
}

// The pixel under a click, from the picture's natural size and its size on screen.
function pixelAt(event) {
  const box = picture.getBoundingClientRect();
  const x = Math.floor(((event.clientX - box.left) * picture.naturalWidth) / box.width);
  const y = Math.floor(((event.clientY - box.top) * picture.naturalHeight) / box.height);
  const clamp = (v, n) => Math.min(Math.max(v, 0), n - 1);
  return { x: clamp(x, picture.naturalWidth), y: clamp(y, picture.naturalHeight) };
}

// Show the picture as large as its column allows: enlarged a whole number of
// times (each pixel a sharp square, up to 8 × 8), or shrunk to fit.
function fit() {
  const width = picture.naturalWidth;
  if (!width) return;
  const room = $("view").clientWidth;
  const zoom = room >= width ? Math.min(8, Math.floor(room / width)) : room / width;
  picture.style.width = `${width * zoom}px`;
  picture.style.height = `${picture.naturalHeight * zoom}px`;
  placeMarker();
}

function placeMarker() {
  const marker = $("marker");
  if (!selected || !picture.naturalWidth) {
    marker.hidden = true;
    return;
  }
  const sx = picture.clientWidth / picture.naturalWidth;
  const sy = picture.clientHeight / picture.naturalHeight;
  const size = Math.max(sx, 6);
  Object.assign(marker.style, {
    left: `${(selected.x + 0.5) * sx - size / 2}px`,
    top: `${(selected.y + 0.5) * sy - size / 2}px`,
    width: `${size}px`,
    height: `${size}px`,
  });
  marker.hidden = false;
}

async function explainPixel() {
  if (!selected) return;
  const mine = ++storyGeneration;
  const query = options();
  query.set("x", selected.x);
  query.set("y", selected.y);
  $("story").dataset.state = "loading";
  const response = await fetch(`/api/pixel?${query}`);
  if (mine !== storyGeneration) return;
  if (!response.ok) {
    const reason = await errorOf(response);
    if (mine !== storyGeneration) return;
    $("story-text").replaceChildren(paragraph(reason, "problem"));
    $("story-json-box").hidden = true;
    $("story").dataset.state = "refused";
    return;
  }
  const text = await response.text();
  if (mine !== storyGeneration) return;
  const story = JSON.parse(text);
  $("story-json").textContent = text;
  $("story-json-box").hidden = false;
  $("story-text").replaceChildren(...tell(story));
  $("story-hint").hidden = true;
  $("story").dataset.x = story.x;
  $("story").dataset.y = story.y;
  $("story").dataset.state = "ready";
}

// Numbers and vectors as the story shows them.
const num = (v) => (v === null || v === undefined ? "—" : Number.isInteger(v) ? String(v) : Number(v).toPrecision(6));
const vec = (v) => (v ? `(${v.map(num).join(", ")})` : "—");

function element(tag, text, className) {
  const e = document.createElement(tag);
  if (text !== undefined) e.textContent = text;
  if (className) e.className = className;
  return e;
}
const paragraph = (text, className) => element("p", text, className);

function table(rows) {
  const t = element("table");
  for (const [name, value] of rows) {
    const tr = element("tr");
    tr.append(element("th", name), element("td", value));
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
  const response = await fetch("/api/scene");
  const scene = await response.json();
  $("scene-name").textContent = scene.file;
  $("scene-version").textContent = `(version ${scene.version})`;
  document.body.dataset.version = scene.version;
  showProblem($("scene-error"), scene.error ? `${scene.error}\n(the picture is of the last scene that loaded)` : "");
  const form = $("controls");
  form.elements.width.placeholder = scene.scene.width;
  form.elements.height.placeholder = scene.scene.height;
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
$("controls").addEventListener("submit", (event) => event.preventDefault());
picture.addEventListener("click", (event) => {
  if (!picture.naturalWidth) return;
  selected = pixelAt(event);
  placeMarker();
  explainPixel();
});
window.addEventListener("resize", fit);

const events = new EventSource("/api/events");
events.onmessage = async (event) => {
  const change = JSON.parse(event.data);
  await loadScene();
  if (!change.error) changed();
};

loadScene().then(render);
