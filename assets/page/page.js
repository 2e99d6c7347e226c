// The behaviour of index.html: build the grid, show the chosen picture large, and
// read the numbers of the pixel under the pointer.
"use strict";

const W = MANIFEST.width;
const H = MANIFEST.height;

// Which buffer (PNG) shows each field of pixels.js. A stage that did not write
// that buffer did not compute the field: the page shows "—" for it.
const BUFFER_OF = {
  R: "beauty", G: "beauty", B: "beauty",
  depth: "depth",
  "N.X": "normal", "N.Y": "normal", "N.Z": "normal",
  "P.X": "position", "P.Y": "position", "P.Z": "position",
  shadow: "shadow",
  object: "object",
  bounces: "bounces",
  rays: "rays",
};

// ---------------------------------------------------------------------------
// 1. The numbers behind the pictures.
//
// Browsers refuse fetch() of local files, but they do run a local <script src>.
// So each stage's numbers are a script, <stage>/pixels.js, which calls
//   raystepPixels.load("06-plane", {width, height, fields: [{name, data}, ...]})
// with an entry for each field the stage computed. raystep packs each field's
// float32s (src/io/page.rs, pack_field): the differences of neighbouring pixels'
// bits, their bytes laid out plane by plane, then zlib, then base64. unpack()
// undoes it, exactly: the page shows the float32s buffers.exr holds.

// folder -> "loading" | "failed" | {width, height, values: {field: Float32Array}}
const stageData = new Map();

window.raystepPixels = {
  load(folder, info) {
    const count = info.width * info.height;
    Promise.all(info.fields.map((field) => unpack(field.data, count)))
      .then((planes) => {
        const values = {};
        info.fields.forEach((field, i) => {
          values[field.name] = planes[i];
        });
        stageData.set(folder, { width: info.width, height: info.height, values });
      })
      .catch((error) => {
        stageData.set(folder, "failed");
        console.warn("cannot read " + folder + "/pixels.js: " + error);
      })
      .finally(show);
  },
};

function base64Bytes(text) {
  const binary = atob(text); // one character per byte
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; i++) {
    bytes[i] = binary.charCodeAt(i);
  }
  return bytes;
}

// One field's `count` float32s from its packed text: base64, then zlib (the
// browser's own DecompressionStream), then the bytes of each difference taken
// from the four planes and added to the value before.
async function unpack(text, count) {
  const zlib = new Blob([base64Bytes(text)]).stream().pipeThrough(new DecompressionStream("deflate"));
  const planes = new Uint8Array(await new Response(zlib).arrayBuffer());
  if (planes.length !== 4 * count) {
    throw new Error(planes.length + " bytes, not " + 4 * count);
  }
  const bits = new Uint32Array(count);
  let before = 0;
  for (let i = 0; i < count; i++) {
    const difference =
      planes[i] | (planes[count + i] << 8) | (planes[2 * count + i] << 16) | (planes[3 * count + i] << 24);
    before = (before + difference) >>> 0; // wrapping, as raystep subtracted
    bits[i] = before;
  }
  return new Float32Array(bits.buffer); // the same bits, read as float32s
}

function loadStage(folder) {
  if (stageData.has(folder)) {
    return; // loaded, loading, or failed already
  }
  if (!MANIFEST.numbers) {
    stageData.set(folder, "absent"); // too large a render: raystep did not write them
    return;
  }
  stageData.set(folder, "loading");
  const script = document.createElement("script");
  script.src = folder + "/pixels.js";
  script.onerror = () => {
    stageData.set(folder, "failed");
    show();
  };
  document.head.append(script);
}

// Every field of pixel (x, y) the stage computed, as numbers.
function pixelValues(data, x, y) {
  const values = {};
  for (const [field, plane] of Object.entries(data.values)) {
    values[field] = plane[y * data.width + x];
  }
  return values;
}

// ---------------------------------------------------------------------------
// 2. The grid: a row per stage, a column per buffer.

const grid = document.getElementById("grid");
const cells = []; // every button, to mark the chosen one

function buildGrid() {
  const head = grid.insertRow();
  head.append(document.createElement("th"));
  for (const buffer of MANIFEST.buffers) {
    const th = document.createElement("th");
    th.scope = "col";
    th.textContent = buffer;
    head.append(th);
  }
  for (const stage of MANIFEST.stages) {
    const row = grid.insertRow();
    const th = document.createElement("th");
    th.scope = "row";
    th.textContent = stage.label;
    row.append(th);
    for (const buffer of MANIFEST.buffers) {
      const td = row.insertCell();
      if (!stage.buffers.includes(buffer)) {
        td.className = "empty"; // this stage does not write this buffer
        td.title = stage.label + " does not write " + buffer;
        continue;
      }
      // A <button> can be reached with Tab and pressed with Enter or Space.
      const button = document.createElement("button");
      button.className = "cell";
      button.dataset.stage = stage.folder;
      button.dataset.buffer = buffer;
      button.setAttribute("aria-pressed", "false");
      button.setAttribute("aria-label", stage.label + ": " + buffer);
      const img = document.createElement("img");
      img.src = stage.folder + "/" + buffer + ".png";
      img.alt = "";
      img.width = W; // the size (CSS makes it smaller) keeps the room for the
      img.height = H; // picture in the layout before it is loaded
      button.append(img);
      button.addEventListener("click", () => choose(stage, buffer));
      td.append(button);
      cells.push(button);
    }
  }
}

// ---------------------------------------------------------------------------
// 3. The chosen picture, large.

const picture = document.getElementById("picture");
const large = document.getElementById("large");
const marker = document.getElementById("marker");
let chosen = null; // {stage, buffer}
let pointer = null; // {x, y}: the pixel being read

function choose(stage, buffer) {
  chosen = { stage, buffer };
  for (const cell of cells) {
    const on = cell.dataset.stage === stage.folder && cell.dataset.buffer === buffer;
    cell.setAttribute("aria-pressed", String(on));
  }
  document.getElementById("picture-title").textContent = stage.label + ": " + buffer;
  large.src = stage.folder + "/" + buffer + ".png";
  large.alt = buffer + " of stage " + stage.label;
  loadStage(stage.folder);
  show();
}

// Enlarge by a whole number of times (every pixel then the same size on screen)
// to fill the window below the grid; a picture too large for that room fills the
// whole window's height instead (scroll down to it), or shrinks to fit it.
function fitLarge() {
  const roomW = picture.clientWidth;
  const top = large.getBoundingClientRect().top + window.scrollY;
  let roomH = window.innerHeight - top - 16;
  if (roomH < H) {
    roomH = window.innerHeight - 60;
  }
  let scale = Math.min(roomW / W, roomH / H);
  if (scale >= 1) {
    scale = Math.floor(scale);
  }
  large.style.width = W * scale + "px";
  large.style.height = H * scale + "px";
  show();
}

// The pixel under a point of the screen.
function pixelAt(clientX, clientY) {
  const box = large.getBoundingClientRect();
  const x = Math.floor(((clientX - box.left) / box.width) * W);
  const y = Math.floor(((clientY - box.top) / box.height) * H);
  return { x: Math.min(Math.max(x, 0), W - 1), y: Math.min(Math.max(y, 0), H - 1) };
}

large.addEventListener("pointermove", (event) => {
  pointer = pixelAt(event.clientX, event.clientY);
  show();
});

// The arrow keys move the pixel read by one (by ten with Shift).
picture.addEventListener("keydown", (event) => {
  const step = event.shiftKey ? 10 : 1;
  const moves = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step] };
  const move = moves[event.key];
  if (!move) {
    return;
  }
  event.preventDefault(); // do not scroll the page
  const from = pointer || { x: Math.floor(W / 2), y: Math.floor(H / 2) };
  pointer = {
    x: Math.min(Math.max(from.x + move[0], 0), W - 1),
    y: Math.min(Math.max(from.y + move[1], 0), H - 1),
  };
  show();
});

// ---------------------------------------------------------------------------
// 4. The readout: the numbers of the pixel being read.

const readout = document.getElementById("readout");
const fieldCells = readout.querySelectorAll("[data-field]");

// About 6 significant digits, for people (the exact value is in data-value).
function rounded(v) {
  if (v === Infinity) return "∞";
  if (v === -Infinity) return "−∞";
  if (Number.isInteger(v)) return String(v);
  return String(Number(v.toPrecision(6)));
}

// A value as text, with what the special values mean.
function describe(field, v) {
  if (field === "depth" && v === Infinity) return "∞ (miss)";
  if (field === "shadow" && v === 1) return "1 (lit)";
  if (field === "shadow" && v === 0) return "0 (in shadow)";
  if ((field === "shadow" || field === "object") && v === -1) return "−1 (miss)";
  return rounded(v);
}

function show() {
  if (!chosen) {
    return;
  }
  const folder = chosen.stage.folder;
  const data = stageData.get(folder);
  document.getElementById("source").textContent = folder + "/pixels.js";
  placeMarker();

  let state;
  let status = "";
  if (data === "absent") {
    state = "absent";
    status =
      "This render is too large for the page to hold its numbers (pixels.js is written up to " +
      MANIFEST.numbersUpTo +
      " pixels). Read any pixel in the studio: raystep serve, then open the address it prints" +
      " and click the pixel; or raystep explain --pixel " +
      (pointer ? pointer.x + "," + pointer.y : "X,Y") +
      " (and the same size flags); or open buffers.exr.";
  } else if (data === "failed") {
    state = "error";
    status =
      "Cannot read " +
      folder +
      "/pixels.js: run raystep stages again to write it (a browser older than 2023 may lack the" +
      " DecompressionStream it needs).";
  } else if (!pointer) {
    state = "empty";
    status = "Point at the picture to read a pixel.";
  } else if (data === "loading" || data === undefined) {
    state = "loading";
    status = "Loading " + folder + "/pixels.js …";
  } else {
    state = "ready";
    const values = pixelValues(data, pointer.x, pointer.y);
    for (const cell of fieldCells) {
      const field = cell.dataset.field;
      const v = values[field];
      const computed = chosen.stage.buffers.includes(BUFFER_OF[field]) && field in values;
      cell.dataset.value = String(v); // exact: the float32 as JavaScript prints it
      cell.dataset.computed = String(computed);
      cell.textContent = computed ? describe(field, v) : "—";
    }
    const [r, g, b] = ["R", "G", "B"].map((c) => Math.round(Math.min(Math.max(values[c], 0), 1) * 255));
    document.getElementById("swatch").style.background = `rgb(${r}, ${g}, ${b})`;
    if (chosen.stage.buffers.includes("depth")) {
      status = values.depth === Infinity ? "Miss: the ray hits nothing." : "Hit.";
    } else {
      status = "This stage casts rays but intersects nothing.";
    }
  }
  document.getElementById("status").textContent = status;
  document.getElementById("where").textContent = pointer ? "x " + pointer.x + ", y " + pointer.y : "";
  // Set last, so that whoever waits for them finds the values above in place.
  readout.dataset.stage = folder;
  readout.dataset.buffer = chosen.buffer;
  readout.dataset.x = pointer ? String(pointer.x) : "";
  readout.dataset.y = pointer ? String(pointer.y) : "";
  readout.dataset.state = state;
}

// Outline the pixel being read (at least 7 screen pixels wide, to be seen).
function placeMarker() {
  if (!pointer) {
    marker.hidden = true;
    return;
  }
  const scale = large.clientWidth / W;
  const size = Math.max(scale + 4, 7);
  marker.hidden = false;
  marker.style.left = (pointer.x + 0.5) * scale - size / 2 + "px";
  marker.style.top = (pointer.y + 0.5) * scale - size / 2 + "px";
  marker.style.width = size + "px";
  marker.style.height = size + "px";
}

// ---------------------------------------------------------------------------
// 5. Start: the grid, and the last stage's picture chosen.

document.getElementById("scene").textContent =
  MANIFEST.scene + " at " + W + " × " + H + ", " + MANIFEST.stages.length + " stages";
buildGrid();
window.addEventListener("resize", fitLarge);
const last = MANIFEST.stages[MANIFEST.stages.length - 1];
if (last) {
  choose(last, last.buffers[0]);
}
fitLarge();
