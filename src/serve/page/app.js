// The page of `glossmeter serve` (docs/serve.md §The page). Plain JavaScript, no library: the recipe editor
// is generated from /api/registry; every number shown comes from the server's documents, which are the
// command line's (`measure`, `sweep`, `compare`, `fit`); pictures are the SVG the library draws.
"use strict";

const $ = (id) => document.getElementById(id);
const state = {
  registry: null, // {models, parameters, colour_conditions}
  geometries: [],
  recipe: null, // the recipe object being edited
  measureSeq: 0, // the latest measure request; older answers are dropped
  measureAbort: null,
  pictureSeq: 0,
  pictureAbort: null,
  sheet: null, // {name, base64}
  compareDoc: null,
  fitRecipe: null,
  sweepText: "",
  sweepRows: [],
  sweepPtr: "",
  doc: null, // the current recipe's measure document
  pinned: null, // {name, recipe, geometries, conditions, doc}: the reference
  savedText: "", // the recipe as last saved or loaded (JSON)
  tables: { data_dir: false, models: [] }, // /api/tables: the table files a recipe may name, per model
};

// ---- small helpers ----------------------------------------------------------------------------------

function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (k === "class") e.className = v;
    else if (k === "text") e.textContent = v;
    else if (v !== undefined && v !== null && v !== false) e.setAttribute(k, v === true ? "" : v);
  }
  for (const c of children) if (c !== null && c !== undefined) e.append(c);
  return e;
}

function debounce(fn, ms) {
  let t = null;
  return (...a) => {
    clearTimeout(t);
    t = setTimeout(() => fn(...a), ms);
  };
}

function status(text) {
  $("status").textContent = text;
}

/// POST a JSON body; resolves to the Response, rejects with the server's message on a non-2xx answer.
async function post(path, body, signal) {
  const r = await fetch(path, {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify(body),
    signal,
  });
  if (!r.ok) {
    let msg = `${r.status} ${r.statusText}`;
    try {
      msg = (await r.json()).error || msg;
    } catch (_) {
      /* not JSON */
    }
    const e = new Error(msg);
    e.status = r.status;
    throw e;
  }
  return r;
}

function isAbort(e) {
  return e && e.name === "AbortError";
}

function shown(v, err) {
  if (v === null || v === undefined) return "—";
  if (typeof v !== "number") return String(v);
  let d = 4;
  if (err && err > 0 && isFinite(err)) d = Math.max(0, Math.min(12, 1 - Math.floor(Math.log10(err))));
  const a = Math.abs(v);
  if (a !== 0 && (a < 1e-4 || a >= 1e9)) return v.toExponential(Math.min(d, 6));
  return v.toFixed(Math.min(d, 6));
}

function download(name, text, type) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = el("a", { href: url, download: name });
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}

function showSvg(img, svgText) {
  const old = img.getAttribute("src");
  img.src = URL.createObjectURL(new Blob([svgText], { type: "image/svg+xml" }));
  if (old && old.startsWith("blob:")) URL.revokeObjectURL(old);
}

// ---- JSON Pointers ----------------------------------------------------------------------------------

function tokens(p) {
  return p.split("/").slice(1).map((t) => t.replace(/~1/g, "/").replace(/~0/g, "~"));
}
function getAt(obj, p) {
  let v = obj;
  for (const t of tokens(p)) {
    if (v === null || typeof v !== "object" || !(t in v)) return undefined;
    v = v[t];
  }
  return v;
}
function setAt(obj, p, value) {
  const ts = tokens(p);
  let v = obj;
  for (const t of ts.slice(0, -1)) {
    if (v[t] === null || typeof v[t] !== "object") v[t] = {};
    v = v[t];
  }
  const last = ts[ts.length - 1];
  if (value === undefined) delete v[last];
  else v[last] = value;
}
function parentOf(p) {
  return p.slice(0, p.lastIndexOf("/"));
}

/// The concrete pointers of a registry pattern (`*` = every index present in the recipe).
function expand(pattern, recipe) {
  const i = pattern.indexOf("/*");
  if (i < 0) return [pattern];
  const arr = getAt(recipe, pattern.slice(0, i));
  if (!Array.isArray(arr)) return [];
  const out = [];
  arr.forEach((_, k) => out.push(...expand(pattern.slice(0, i) + "/" + k + pattern.slice(i + 2), recipe)));
  return out;
}

// ---- numbers typed by people ------------------------------------------------------------------------

/// A number as typed: a decimal point or a decimal comma (`0,05` is 0.05); a comma beside a point, or two
/// commas, is refused rather than guessed (NaN).
function parseNumber(text) {
  let t = String(text).trim().replace(/\s/g, "");
  if (t === "") return NaN;
  const commas = (t.match(/,/g) || []).length;
  if (commas > 1 || (commas === 1 && t.includes("."))) return NaN;
  t = t.replace(",", ".");
  if (!/^[+-]?(\d+\.?\d*|\.\d+)(e[+-]?\d+)?$/i.test(t)) return NaN;
  return Number(t);
}

/// A number input that takes a decimal comma (`type=number` would drop it): text with a decimal keypad.
function numberInput(attrs) {
  return el("input", { type: "text", inputmode: "decimal", autocomplete: "off", class: "number", ...attrs });
}

// ---- names people use -------------------------------------------------------------------------------

const WORDS = { ior: "refractive index", um: "µm", nm: "nm", mm: "mm", deg: "°", tio2: "TiO₂", rgb: "RGB" };

/// A JSON Pointer as words: `/clear_coat/roughness` → "clear coat · roughness"; array elements by their
/// `name` (pigment 1 "cerulean blue").
function label(ptr, recipe) {
  const ts = tokens(ptr);
  const out = [];
  let node = recipe;
  ts.forEach((t, i) => {
    const next = node && typeof node === "object" ? node[t] : undefined;
    if (/^\d+$/.test(t)) {
      const parent = ts[i - 1] || "";
      const one = parent.replace(/s$/, "").replace(/_/g, " ");
      const name = next && typeof next === "object" && next.name ? ` “${next.name}”` : "";
      if (Array.isArray(next) || typeof next !== "object" || next === null) out.push(`[${Number(t) + 1}]`);
      else out[out.length - 1] = `${one} ${Number(t) + 1}${name}`;
    } else {
      out.push(t.split("_").map((w) => WORDS[w] || w).join(" ").replace(/ (µm|nm|mm|°)$/, " ($1)").replace(/ \(?(µm|nm|mm)\)?$/, " ($1)"));
    }
    node = next;
  });
  return out.join(" · ").replace(/ · \[/g, " [");
}

// ---- the recipe editor ------------------------------------------------------------------------------

/// The registry entry of `ptr`: array elements of objects match the entry's `*`, and an element of a numeric
/// array (`/albedo/0`) takes the array's entry, whose range bounds each element.
function entryOf(ptr, model) {
  const pattern = ptr.replace(/\/\d+(?=\/|$)/g, "/*");
  const array = ptr.replace(/\/\d+$/, "");
  const of = (want) => state.registry.parameters.find((q) => q.models.includes(model) && q.pointer === want);
  return of(ptr) || of(pattern) || (array !== ptr && of(array.replace(/\/\d+(?=\/|$)/g, "/*"))) || undefined;
}

/// The fields the editor shows for the recipe: every registry entry of its model whose parent object is in
/// the recipe, set or not (an unset one shows its default).
function fieldsOf(recipe) {
  const model = recipe.model;
  const out = [];
  for (const p of state.registry.parameters) {
    if (!p.models.includes(model) || p.pointer === "/model") continue;
    if (p.type === "object" || p.type === "array of objects") continue;
    for (const ptr of expand(p.pointer, recipe)) {
      const parent = parentOf(ptr);
      if (parent !== "" && getAt(recipe, parent) === undefined) continue;
      out.push({ p, ptr });
    }
  }
  return out;
}

/// The optional blocks and lists of objects of the model (flakes, a coat, pigments, lobes): what the editor
/// can add or remove.
function blocksOf(recipe) {
  return state.registry.parameters.filter(
    (p) => p.models.includes(recipe.model) && (p.type === "object" || p.type === "array of objects") && !p.pointer.includes("*"),
  );
}

/// A block's starting value: the recipe's own last element (a list), else the block of the first shipped
/// recipe of the model that has it and the same spectral sampling (`/wavelengths_nm`).
function template(ptr, recipe) {
  const own = getAt(recipe, ptr);
  if (Array.isArray(own) && own.length) return JSON.parse(JSON.stringify(own[own.length - 1]));
  const same = (r) => JSON.stringify(r.wavelengths_nm) === JSON.stringify(recipe.wavelengths_nm);
  const candidates = state.fixtures.map((f) => JSON.parse(f.recipe)).filter((r) => r.model === recipe.model);
  for (const r of [...candidates.filter(same), ...candidates]) {
    const v = getAt(r, ptr);
    if (Array.isArray(v) && v.length) return JSON.parse(JSON.stringify(v[0]));
    if (v !== undefined && !Array.isArray(v)) return JSON.parse(JSON.stringify(v));
  }
  return null;
}

function blockId(ptr) {
  return ptr.slice(1).replace(/[^A-Za-z0-9]/g, "_");
}

function fieldId(ptr) {
  return "f" + ptr.replace(/[^A-Za-z0-9]/g, "_");
}

function buildForm() {
  const form = $("params");
  form.replaceChildren();
  const r = state.recipe;
  for (const { p, ptr } of fieldsOf(r)) {
    const id = fieldId(ptr);
    const v = getAt(r, ptr);
    let input;
    if (p.choices) {
      input = el("select", { id });
      if (!p.required) input.append(el("option", { value: "", text: `(default ${p.default})` }));
      for (const c of p.choices) input.append(el("option", { value: c, text: c }));
      input.value = v === undefined ? "" : v;
    } else if (p.type === "boolean") {
      input = el("select", { id });
      input.append(el("option", { value: "", text: p.required ? "" : `(default ${p.default})` }));
      input.append(el("option", { value: "true", text: "true" }), el("option", { value: "false", text: "false" }));
      input.value = v === undefined ? "" : String(v);
    } else if (p.number) {
      input = numberInput({ id, placeholder: p.required ? "required" : `default ${p.default}` });
      input.value = typeof v === "number" ? String(v) : "";
    } else if (tableOf(r.model) && ptr === "/file") {
      // A table model's file: the tables of the server's data directory that the model reads (/api/tables).
      const t = tableOf(r.model);
      input = el("input", { id, type: "text", list: id + "-tables", placeholder: tablePlaceholder(t) });
      input.value = typeof v === "string" ? v : "";
      form.append(el("datalist", { id: id + "-tables" }, ...t.files.map((f) => el("option", { value: f }))));
    } else {
      // Colours, spectra, arrays, indices, text: the JSON of the value (text fields: the string).
      const text = p.numeric || typeof v !== "string" ? (v === undefined ? "" : JSON.stringify(v)) : v;
      input = el("input", { id, type: "text", placeholder: p.required ? "required" : `default ${p.default}` });
      input.value = text;
    }
    input.dataset.pointer = ptr;
    const unit = p.unit ? ` (${p.unit})` : "";
    const range = p.range ? ` ${p.range.text}` : "";
    const set = v === undefined ? (p.required ? "; required" : `; not set: the model assumes ${p.default}`) : "";
    const help = el("span", { class: "doc", id: id + "-doc", text: `${p.description}; ${p.type}${range}${set}` });
    input.setAttribute("aria-describedby", id + "-doc");
    input.title = ptr;
    const lab = el("label", { for: id }, label(ptr, r) + unit, el("code", { class: "ptr", text: ptr }));
    form.append(el("div", { class: "field" + (v === undefined ? " unset" : "") }, lab, input, help));
    input.addEventListener(input.tagName === "SELECT" ? "change" : "input", () => fieldChanged(input, p));
  }
  buildBlocks();
  buildSweepChoices();
  buildFitChoices();
}

/// Add and remove buttons for the model's optional blocks and its lists of objects.
function buildBlocks() {
  const box = $("blocks");
  box.replaceChildren();
  const r = state.recipe;
  for (const b of blocksOf(r)) {
    const v = getAt(r, b.pointer);
    const name = label(b.pointer, r);
    if (b.type === "array of objects") {
      const one = name.replace(/s$/, "").replace(/^.* · /, "");
      const add = el("button", { type: "button", id: "add-" + blockId(b.pointer), text: `add a ${one}` });
      add.addEventListener("click", () => {
        const t = template(b.pointer, r);
        if (!t) return status(`no shipped ${r.model} recipe has a ${one} to start from; add it in the raw JSON`);
        if (t.name !== undefined) t.name = `${one} ${(Array.isArray(v) ? v.length : 0) + 1}`;
        setAt(r, b.pointer, [...(Array.isArray(v) ? v : []), t]);
        edited();
      });
      box.append(add);
      (Array.isArray(v) ? v : []).forEach((_, i) => {
        const rm = el("button", { type: "button", class: "remove", text: `remove ${label(b.pointer + "/" + i, r).replace(/^.* · /, "")}` });
        rm.addEventListener("click", () => {
          v.splice(i, 1);
          edited();
        });
        box.append(rm);
      });
    } else if (!b.required && (parentOf(b.pointer) === "" || getAt(r, parentOf(b.pointer)) !== undefined)) {
      const has = v !== undefined;
      const btn = el("button", { type: "button", id: (has ? "remove-" : "add-") + blockId(b.pointer), text: `${has ? "remove" : "add"} ${name}` });
      btn.addEventListener("click", () => {
        if (has) setAt(r, b.pointer, undefined);
        else {
          const t = template(b.pointer, r);
          if (!t) return status(`no shipped ${r.model} recipe has ${name} to start from; add it in the raw JSON`);
          // Flakes lie inside the pigmented layer (their depth at most its thickness): a template's depth
          // deeper than this recipe's layer is put at the layer's middle.
          const x = getAt(r, "/pigmented_layer/thickness_mm");
          if (typeof t.depth_mm === "number" && typeof x === "number" && t.depth_mm > x) t.depth_mm = x / 2;
          setAt(r, b.pointer, t);
        }
        edited();
      });
      box.append(btn);
    }
  }
}

/// After the editor changed the recipe's shape: the raw view, the fields and the readings.
function edited() {
  writeRaw();
  buildForm();
  recipeChanged();
}

function fieldChanged(input, p) {
  const ptr = input.dataset.pointer;
  const t = input.value.trim();
  let value;
  input.classList.remove("bad");
  input.removeAttribute("aria-invalid");
  const bad = () => {
    input.classList.add("bad");
    input.setAttribute("aria-invalid", "true");
  };
  if (t === "") value = undefined;
  else if (p.number) {
    value = parseNumber(t);
    if (!isFinite(value)) return bad();
  } else if (p.type === "boolean") value = t === "true";
  else if (p.choices) value = t;
  else if (p.numeric) {
    const n = parseNumber(t);
    if (isFinite(n)) value = n;
    else {
      try {
        value = JSON.parse(t);
      } catch (_) {
        return bad();
      }
    }
  } else value = t;
  setAt(state.recipe, ptr, value);
  writeRaw();
  recipeChanged();
}

function writeRaw() {
  $("raw").value = JSON.stringify(state.recipe, null, 2);
  $("raw-error").textContent = "";
}

const rawChanged = debounce(() => {
  let r;
  try {
    r = JSON.parse($("raw").value);
  } catch (e) {
    $("raw-error").textContent = "not valid JSON: " + e.message;
    return;
  }
  if (r === null || typeof r !== "object" || Array.isArray(r)) {
    $("raw-error").textContent = "a recipe is a JSON object";
    return;
  }
  $("raw-error").textContent = "";
  state.recipe = r;
  $("model").value = r.model || "";
  buildForm();
  recipeChanged();
}, 400);

/// Show a recipe in the editor; `saved` says it is what a file, a shipped recipe or the browser holds (so
/// that leaving the page loses nothing).
function setRecipe(r, saved = true) {
  state.recipe = r;
  $("model").value = r.model || "";
  writeRaw();
  buildForm();
  recipeChanged();
  if (saved) markSaved();
  $("saved-list").value = "";
}

/// Another model: the fields the two models share are kept, and every required block or field of the new
/// model is filled from the model's first shipped recipe (the registry gives the optional fields' defaults).
function modelChanged() {
  const model = $("model").value;
  const old = state.recipe;
  const r = { model };
  for (const k of ["name", "description", "provenance", "notes"]) if (k in old) r[k] = old[k];
  for (const p of state.registry.parameters) {
    if (!p.models.includes(model) || p.pointer.split("/").length !== 2 || p.pointer === "/model") continue;
    const v = getAt(old, p.pointer);
    const before = entryOf(p.pointer, old.model);
    // Another model's table is kept only when this model reads its kind of file.
    const t = p.pointer === "/file" ? tableOf(model) : null;
    if (t && !(typeof v === "string" && t.extensions.some((e) => v.endsWith(e)))) continue;
    if (v !== undefined && before && before.type === p.type) setAt(r, p.pointer, v);
  }
  const first = state.fixtures.map((f) => JSON.parse(f.recipe)).find((f) => f.model === model);
  const filled = [];
  for (const p of state.registry.parameters) {
    // Required, or one of a group of which one must be given (its default says "give …").
    const needed = p.required || /\bgive\b/.test(String(p.default));
    if (!p.models.includes(model) || !needed || p.pointer.split("/").length !== 2 || getAt(r, p.pointer) !== undefined) continue;
    const v = first ? getAt(first, p.pointer) : undefined;
    if (v !== undefined) {
      setAt(r, p.pointer, JSON.parse(JSON.stringify(v)));
      filled.push(label(p.pointer, r));
    }
  }
  // A model whose roughness and populations are alternatives: the shipped recipe's choice.
  if (first && first.populations && r.roughness === undefined && r.populations === undefined) r.populations = first.populations;
  // A table model: the first table of the server's data directory that it reads (no shipped recipe names
  // one there); none: the field and the readings say what is needed and where it may come from.
  const t = tableOf(model);
  let words = filled.length ? `${model}: ${filled.join(", ")} filled from the shipped recipe “${first.name || ""}”` : `${model}`;
  if (t && r.file === undefined && t.files.length) {
    r.file = t.files[0];
    words = `${model}: file “${r.file}”, the first of the ${t.files.length} ${t.extensions.join(" or ")} table(s) in the server's data directory`;
  } else if (t && r.file === undefined) words = `${model}: ${tablePlaceholder(t)}`;
  setRecipe(r, false);
  status(words);
}

/// The table files of a table model (`{model, extensions, files}` of /api/tables), or null.
function tableOf(model) {
  return state.tables.models.find((m) => m.model === model) || null;
}

function tablePlaceholder(t) {
  const kind = `a ${t.extensions.join(" or ")} table`;
  if (t.files.length) return `${kind} in the server's data directory: ${t.files.join(", ")}`;
  return state.tables.data_dir
    ? `${kind} in the server's data directory (it holds none: put one there)`
    : `${kind} in the server's data directory: this server has none (start it with glossmeter serve --data-dir DIR)`;
}

/// The required top-level fields the recipe does not set, with what each allows (a switch of model to one no
/// shipped recipe fills, a table model without a table): shown in place of the readings, not as an error.
function missingRequired(r) {
  if (!state.registry || !r.model || !state.registry.models.includes(r.model)) return [];
  return state.registry.parameters
    .filter((p) => p.models.includes(r.model) && p.required && p.pointer !== "/model" && p.pointer.split("/").length === 2 && getAt(r, p.pointer) === undefined)
    .map((p) => {
      const t = tableOf(r.model);
      const allowed = t && p.pointer === "/file" ? tablePlaceholder(t) : `${p.type}${p.range ? " " + p.range.text : ""}${p.unit ? " (" + p.unit + ")" : ""}: ${p.description}`;
      return { pointer: p.pointer, text: `${label(p.pointer, r)}: ${allowed}` };
    });
}

// ---- save and load ----------------------------------------------------------------------------------

const DRAFT = "glossmeter.draft";
const SAVED = "glossmeter.saved";

function savedRecipes() {
  try {
    return JSON.parse(localStorage.getItem(SAVED) || "{}");
  } catch (_) {
    return {};
  }
}

function markSaved() {
  state.savedText = JSON.stringify(state.recipe);
  unsavedChanged();
}

function unsaved() {
  return state.savedText !== JSON.stringify(state.recipe);
}

function unsavedChanged() {
  const u = unsaved();
  document.body.dataset.unsaved = String(u);
  $("save-state").textContent = u ? "unsaved edits (kept in this browser as a draft)" : "saved";
  if (u) localStorage.setItem(DRAFT, JSON.stringify({ recipe: state.recipe, at: new Date().toISOString() }));
  else localStorage.removeItem(DRAFT);
}

function fileName(r) {
  return ((r.name || r.model || "recipe").replace(/[^A-Za-z0-9._-]+/g, "-").replace(/^-|-$/g, "").slice(0, 60) || "recipe") + ".json";
}

function saveFile() {
  download(fileName(state.recipe), JSON.stringify(state.recipe, null, 2) + "\n", "application/json");
  markSaved();
  status(`saved as ${fileName(state.recipe)} (your browser's downloads)`);
}

async function openFile() {
  const f = $("open-file").files[0];
  if (!f) return;
  try {
    const r = JSON.parse(await f.text());
    if (r === null || typeof r !== "object" || Array.isArray(r)) throw new Error("a recipe is a JSON object");
    setRecipe(r);
    status(`opened ${f.name}`);
  } catch (e) {
    status(`${f.name}: not a recipe: ${e.message}`);
  } finally {
    $("open-file").value = "";
  }
}

function listSaved() {
  const sel = $("saved-list");
  sel.replaceChildren(el("option", { value: "", text: "(saved in this browser)" }));
  for (const name of Object.keys(savedRecipes()).sort()) sel.append(el("option", { value: name, text: name }));
}

function saveBrowser() {
  const name = (state.recipe.name || state.recipe.model || "recipe").trim();
  const all = savedRecipes();
  all[name] = state.recipe;
  localStorage.setItem(SAVED, JSON.stringify(all));
  listSaved();
  $("saved-list").value = name;
  markSaved();
  status(`saved “${name}” in this browser`);
}

function loadBrowser() {
  const name = $("saved-list").value;
  if (!name) return;
  const r = savedRecipes()[name];
  if (!r) return;
  if (unsaved() && !confirm("Your edits are not saved. Load the saved recipe anyway?")) return;
  setRecipe(JSON.parse(JSON.stringify(r)));
  $("saved-list").value = name;
  status(`loaded “${name}” from this browser`);
}

// ---- readings ---------------------------------------------------------------------------------------

function chosenGeometries() {
  return [...document.querySelectorAll("#geometries input:checked")].map((i) => i.value);
}

/// The illuminant and observer every colour reading is computed under (the request fields `illuminant` and
/// `observer`, as `measure --illuminant --observer`): every request that reads colour carries them.
function conditions() {
  return { illuminant: $("illuminant").value, observer: $("observer").value };
}

/// "A / 2°": the conditions as a caption says them.
function conditionsText(c) {
  return `${c.illuminant} / ${c.observer}°`;
}

const CONDITIONS = "glossmeter.colour-conditions";

/// The illuminant and observer choices, from /api/registry; the last choice of this browser is kept.
function buildConditions(offered) {
  let kept = null;
  try {
    kept = JSON.parse(localStorage.getItem(CONDITIONS) || "null");
  } catch (_) {
    kept = null;
  }
  for (const [key, list] of [["illuminant", offered.illuminants], ["observer", offered.observers]]) {
    const select = $(key);
    for (const x of list) select.append(el("option", { value: x.id, text: x.title }));
    const want = kept && list.some((x) => x.id === kept[key]) ? kept[key] : offered.default[key];
    select.value = want;
    select.addEventListener("change", conditionsChanged);
  }
}

function conditionsChanged() {
  localStorage.setItem(CONDITIONS, JSON.stringify(conditions()));
  recipeChanged();
  remeasurePinned();
}

function markStale(text) {
  $("readings").classList.add("stale");
  $("readings").setAttribute("aria-busy", "true");
  $("readings-state").textContent = text;
}

const measureSoon = debounce(measure, 300);

function recipeChanged() {
  // Whatever is under way describes an older recipe: it will never be shown as current.
  state.measureSeq += 1;
  if (state.measureAbort) state.measureAbort.abort();
  markStale("computing…");
  measureSoon();
  if ($("picture-live").checked && !$("panel-pictures").hidden) pictureSoon();
  unsavedChanged();
}

/// The measure document of `recipe` through `geos`. A colour geometry the library refuses for this recipe (an
/// RGB recipe has no spectrum, so no X, Y, Z: docs/colour.md) is left out by the server, the others are read,
/// and the document says which and why (`refused`: {geometries, message}, the library's message).
/// The document keeps the colour conditions it was read under (`doc.conditions`, the page's own field), so that
/// a document still shown after the choice changed is never taken to be under the new one.
async function measureDoc(recipe, geos, signal) {
  const c = conditions();
  const doc = await (await post("/api/measure", { recipe, geometries: geos, ...c, omit_refused_colour: true }, signal)).json();
  doc.conditions = c;
  return doc;
}

/// In place of the readings: what the recipe still needs (no request is sent).
function showMissing(missing) {
  state.doc = null;
  const body = $("readings").querySelector("tbody");
  const ul = el("ul", {}, ...missing.map((m) => el("li", { "data-pointer": m.pointer, text: m.text })));
  const cols = $("readings").querySelectorAll("thead th").length || 6;
  body.replaceChildren(el("tr", { class: "missing" }, el("td", { colspan: cols }, el("p", { text: `To read this ${state.recipe.model} recipe, set:` }), ul)));
  $("colours").replaceChildren();
  $("measure-error").textContent = "";
  $("readings").classList.remove("stale");
  $("readings").setAttribute("aria-busy", "false");
  $("readings-state").textContent = "needs a value";
  status(`${state.recipe.model}: ${missing.map((m) => m.pointer).join(", ")} to set`);
}

async function measure() {
  const seq = ++state.measureSeq;
  if (state.measureAbort) state.measureAbort.abort();
  const missing = missingRequired(state.recipe);
  if (missing.length) return showMissing(missing);
  const ctl = new AbortController();
  state.measureAbort = ctl;
  markStale("computing…");
  status("measuring…");
  try {
    const doc = await measureDoc(state.recipe, chosenGeometries(), ctl.signal);
    if (seq !== state.measureSeq) return; // a newer request is under way: never show this one as current
    state.doc = doc;
    showReadings(doc);
    $("measure-error").textContent = "";
    status(`${doc.material.name}: ${doc.readings.length} reading(s)`);
  } catch (e) {
    if (isAbort(e) || seq !== state.measureSeq) return;
    if (e.status === 503) {
      markStale("server busy, retrying…");
      setTimeout(() => seq === state.measureSeq && measure(), 1000);
      return;
    }
    state.doc = null;
    $("measure-error").textContent = e.message;
    $("readings").querySelector("tbody").replaceChildren();
    $("readings").classList.remove("stale");
    $("readings").setAttribute("aria-busy", "false");
    $("readings-state").textContent = "no readings";
    status("the recipe has an error");
  }
}

/// The step an instrument displays a reading in: gloss, haze and DOI meters show one decimal (0.1 GU,
/// 0.1 HU, 0.1 DOI), spectrophotometers two for L*, a*, b*, C* and one for the hue angle (docs/serve.md
/// §The page).
const STEP = { GU: 0.1, HU: 0.1, "HU(log)": 0.1, DOI: 0.1, "°": 0.1, "": 0.01 };

function stepOf(unit) {
  return STEP[unit] === undefined ? 0.01 : STEP[unit];
}

function decimalsOf(step) {
  return Math.max(0, Math.round(-Math.log10(step)));
}

/// A reading as the instrument shows it: rounded to its display step.
function display(v, unit) {
  if (v === null || v === undefined || !isFinite(v)) return "—";
  const d = decimalsOf(stepOf(unit));
  const s = (Math.round(v / stepOf(unit)) * stepOf(unit)).toFixed(d);
  return s === "-" + (0).toFixed(d) ? (0).toFixed(d) : s;
}

function geometryOf(id) {
  return state.geometries.find((g) => g.id === id) || { id, title: id, standards: [], assumed: [] };
}

/// What the numerical error means beside the displayed step: [short words, the full sentence].
function errorWords(r) {
  if (r.value === null) return [r.problem || "no value", r.problem || "no value"];
  const e = r.error_estimate, step = stepOf(r.unit), u = r.unit ? " " + r.unit : "";
  if (!(e >= 0)) return ["", ""];
  if (e < step / 20) return ["exact to the digit shown", `computing error ${e.toExponential(0)}${u}, far below the display step ${step}${u}`];
  if (e < step / 2) return ["last digit ±1", `the last digit may be off by one: computing error ${e.toPrecision(1)}${u} (display step ${step}${u})`];
  return [`NOT exact: good to ${e.toPrecision(2)}${u}`, `the computation is only good to ${e.toPrecision(2)}${u}, more than half the display step ${step}${u}`];
}

/// The geometry's assumed numbers (no retrieved source states them), in words, with the reason on hover.
function assumedBox(g) {
  if (!g.assumed || !g.assumed.length) return el("span", { class: "muted", text: "every number sourced" });
  const d = el("details", { class: "assumed" }, el("summary", { text: `${g.assumed.length} assumed number${g.assumed.length > 1 ? "s" : ""}` }));
  const ul = el("ul");
  for (const a of g.assumed) {
    const words = a.pointer.split("/").slice(1).filter((t) => t !== "value").map((t) => t.replace(/_deg$/, " (°)").replace(/_/g, " ")).join(" · ");
    ul.append(el("li", { title: a.source || "", text: `${words} = ${a.value}: ${String(a.source || "").replace(/^ASSUMED\.\s*/, "")}` }));
  }
  d.append(ul);
  return d;
}

function readingKey(r) {
  return r.geometry + "\u0000" + r.name;
}

function showReadings(doc) {
  const body = $("readings").querySelector("tbody");
  body.replaceChildren();
  const ref = state.pinned && state.pinned.doc ? new Map(state.pinned.doc.readings.map((r) => [readingKey(r), r])) : null;
  $("readings").classList.toggle("pinned", !!ref);
  let last = null;
  for (const r of doc.readings) {
    const g = geometryOf(r.geometry);
    const v = el("td", { class: "num value", text: display(r.value, r.unit) });
    v.dataset.value = r.value === null ? "" : String(r.value);
    v.title = r.value === null ? "no value" : `computed: ${r.value}`;
    const [short, long] = errorWords(r);
    const pu = r.prediction_uncertainty;
    const stated = typeof pu === "number" ? `; from the recipe's stated uncertainties: standard uncertainty ${pu.toPrecision(2)} ${r.unit}` : "";
    const first = r.geometry !== last;
    last = r.geometry;
    const tr = el("tr", { "data-geometry": r.geometry, "data-name": r.name, class: first ? "first" : "more" },
      el("td", { class: "instrument", title: `${g.id}: ${(g.standards || []).join(", ")}`, text: first ? g.title : "" }),
      el("td", { text: r.name }),
      v,
      el("td", { class: "unit", text: r.unit }));
    if (ref) {
      const o = ref.get(readingKey(r));
      const rv = o && o.value !== null ? o.value : null;
      const ref_td = el("td", { class: "num ref", text: rv === null ? "—" : display(rv, r.unit) });
      ref_td.dataset.value = rv === null ? "" : String(rv);
      const dv = rv !== null && r.value !== null ? r.value - rv : null;
      const diff = el("td", { class: "num diff", text: dv === null ? "—" : (dv > 0 ? "+" : "") + display(dv, r.unit) });
      diff.dataset.value = dv === null ? "" : String(dv);
      tr.append(ref_td, diff);
    }
    tr.append(el("td", { class: "note" + (r.converged ? "" : " warn"), title: long + stated, text: short + stated + (r.note ? `; ${r.note}` : "") }), el("td", {}, first ? assumedBox(g) : ""));
    body.append(tr);
  }
  // The colour geometries the library refused for this recipe: a row each, saying why, in place.
  for (const id of doc.refused ? doc.refused.geometries : []) {
    const g = geometryOf(id);
    const tr = el("tr", { "data-geometry": id, "data-name": "", class: "first refused" },
      el("td", { class: "instrument", title: `${g.id}: ${(g.standards || []).join(", ")}`, text: g.title }),
      el("td", { text: "colour" }), el("td", { class: "num value", "data-value": "", text: "—" }), el("td", { class: "unit" }));
    if (ref) tr.append(el("td", { class: "num ref", text: "—" }), el("td", { class: "num diff", text: "—" }));
    tr.append(el("td", { class: "note warn", title: doc.refused.message, text: "no colour: " + refusalWords(doc.refused.message) }), el("td", {}, assumedBox(g)));
    body.append(tr);
  }
  showColours(doc);
  $("readings").classList.remove("stale");
  $("readings").setAttribute("aria-busy", "false");
  $("readings-state").textContent = "current";
}

// ---- colour and the pinned reference ----------------------------------------------------------------

/// L*, a*, b* of a document's colour readings, per geometry (the first colour geometry with all three).
function labOf(doc) {
  const by = new Map();
  for (const r of doc.readings) {
    const m = /^(L\*|a\*|b\*)/.exec(r.name);
    if (!m || r.value === null) continue;
    if (!by.has(r.geometry)) by.set(r.geometry, {});
    by.get(r.geometry)[m[1]] = r.value;
  }
  for (const [g, v] of by) if (v["L*"] !== undefined && v["a*"] !== undefined && v["b*"] !== undefined) return { geometry: g, L: v["L*"], a: v["a*"], b: v["b*"] };
  return null;
}

/// sRGB of CIELAB (D65 white, IEC 61966-2-1), for a swatch on screen only: the readings are the numbers.
function srgbOf(lab) {
  const f = (t) => (t > 6 / 29 ? t ** 3 : 3 * (6 / 29) ** 2 * (t - 4 / 29));
  const fy = (lab.L + 16) / 116;
  const X = 0.95047 * f(fy + lab.a / 500), Y = f(fy), Z = 1.08883 * f(fy - lab.b / 200);
  const lin = [3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z, 0.0557 * X - 0.204 * Y + 1.057 * Z];
  const g = lin.map((c) => Math.round(255 * Math.min(1, Math.max(0, c <= 0.0031308 ? 12.92 * c : 1.055 * c ** (1 / 2.4) - 0.055))));
  return `rgb(${g.join(", ")})`;
}

function swatch(lab, caption) {
  const s = el("div", { class: "swatch" });
  s.style.background = srgbOf(lab);
  return el("figure", { class: "colour" }, s, el("figcaption", { text: `${caption}: L* ${lab.L.toFixed(2)}, a* ${lab.a.toFixed(2)}, b* ${lab.b.toFixed(2)}` }));
}

/// The library's refusal without the geometry ids it starts with (the row names the instrument).
function refusalWords(message) {
  return message.replace(/^(recipe: )?[a-z0-9-]+(, [a-z0-9-]+)*: (?=colour)/, "");
}

function showColours(doc) {
  const box = $("colours");
  box.replaceChildren();
  if (doc.refused) {
    const spectral = (state.fixtures || []).filter((f) => JSON.parse(f.recipe).wavelengths_nm).map((f) => f.name);
    box.append(el("p", { id: "colour-refused", class: "warn" },
      `No colour for this recipe through ${doc.refused.geometries.map((id) => geometryOf(id).title).join(", ")}: ${refusalWords(doc.refused.message)}. ` +
        `Its other readings are shown. Colour needs a spectral recipe: give it "wavelengths_nm" with a value per wavelength` +
        (spectral.length ? `, or start from a shipped spectral one (${spectral.join(", ")}).` : ".")));
  }
  const lab = labOf(doc);
  const ref = state.pinned && state.pinned.doc ? labOf(state.pinned.doc) : null;
  if (!lab && !ref) {
    if (doc.refused) return;
    box.append(el("p", { class: "hint", text: "Tick a colour geometry under Geometries (ASTM E2194 or E2539 multi-angle, the d/8 sphere) to see the colour; it needs a spectral recipe (one with wavelengths_nm)." }));
    return;
  }
  if (lab) box.append(swatch(lab, `this recipe (${geometryOf(lab.geometry).title}, ${conditionsText(doc.conditions)})`));
  if (ref) box.append(swatch(ref, `reference “${state.pinned.name}” (${conditionsText(state.pinned.doc.conditions)})`));
  if (lab && ref) {
    const de = Math.hypot(lab.L - ref.L, lab.a - ref.a, lab.b - ref.b);
    box.append(el("p", { id: "delta-e", text: `ΔE*ab = ${de.toFixed(2)} (ΔL* ${(lab.L - ref.L).toFixed(2)}, Δa* ${(lab.a - ref.a).toFixed(2)}, Δb* ${(lab.b - ref.b).toFixed(2)})` }));
  }
  box.append(el("p", { class: "hint", text: "Swatches are CIELAB shown as sRGB (D65) on this screen: a guide; the numbers are the readings. L*, a*, b* are relative to the white of the chosen illuminant, so under another illuminant the swatch is the colour as an eye adapted to it would see it, not the light itself." }));
}

function pin() {
  if (!state.doc) return status("nothing to pin: the recipe has no readings");
  state.pinned = { name: state.recipe.name || state.recipe.model, recipe: JSON.parse(JSON.stringify(state.recipe)), geometries: chosenGeometries(), conditions: state.doc.conditions, doc: state.doc };
  $("pin-state").textContent = `reference: “${state.pinned.name}”`;
  $("unpin").disabled = false;
  setHeaders();
  showReadings(state.doc);
  // A reading still under way for other geometries or conditions: the reference is read under the current ones.
  remeasurePinned();
}

function unpin() {
  state.pinned = null;
  $("pin-state").textContent = "";
  $("unpin").disabled = true;
  setHeaders();
  if (state.doc) showReadings(state.doc);
}

/// The reference's readings through the geometries now ticked and under the colour conditions now chosen
/// (measured again when either changed), so that a difference is never across two conditions.
async function remeasurePinned() {
  const geos = chosenGeometries(), now = conditions();
  if (!state.pinned || JSON.stringify([state.pinned.geometries, state.pinned.conditions]) === JSON.stringify([geos, now])) return;
  try {
    const doc = await measureDoc(state.pinned.recipe, geos);
    if (state.pinned) Object.assign(state.pinned, { doc, geometries: geos, conditions: now });
    if (state.doc) showReadings(state.doc);
  } catch (e) {
    $("measure-error").textContent = "the reference: " + e.message;
  }
}

function setHeaders() {
  const tr = $("readings").querySelector("thead tr");
  const cols = [["instrument"], ["reading"], ["value", "num", "as the instrument displays it (the computed value on hover)"], ["unit"]];
  if (state.pinned) cols.push(["reference", "num", `the pinned recipe “${state.pinned.name}”`], ["difference", "num", "this recipe − the reference"]);
  cols.push(["how exact", "", "the numerical (computing) error beside the display step; not a measurement uncertainty"], ["assumed by the geometry", "", "numbers of the geometry no retrieved source states"]);
  tr.replaceChildren(...cols.map(([t, c, title]) => el("th", { class: c || null, title: title || null, text: t })));
}

// ---- pictures ---------------------------------------------------------------------------------------

const pictureSoon = debounce(picture, 600);

async function picture() {
  const missing = missingRequired(state.recipe);
  if (missing.length) {
    $("picture-error").textContent = `set ${missing.map((m) => m.pointer).join(", ")} first (see the readings)`;
    return;
  }
  const seq = ++state.pictureSeq;
  if (state.pictureAbort) state.pictureAbort.abort();
  const ctl = new AbortController();
  state.pictureAbort = ctl;
  $("picture").classList.add("stale");
  try {
    const r = await post("/api/plot", { recipe: state.recipe, kind: $("picture-kind").value }, ctl.signal);
    const svg = await r.text();
    if (seq !== state.pictureSeq) return;
    showSvg($("picture"), svg);
    $("picture-error").textContent = "";
    $("picture").classList.remove("stale");
  } catch (e) {
    if (isAbort(e) || seq !== state.pictureSeq) return;
    $("picture-error").textContent = e.message;
  }
}

// ---- numbers to vary and fit ------------------------------------------------------------------------

/// Every number of the model the recipe can take: the registry's numeric entries whose parent object is in
/// the recipe, set or not (an unset one at its default), and each element of a numeric array that is set.
function numberFields() {
  const out = [];
  for (const { p, ptr } of fieldsOf(state.recipe)) {
    if (!p.numeric || !p.range) continue;
    const v = getAt(state.recipe, ptr);
    if (p.number || typeof v === "number") out.push({ p, ptr });
    else if (Array.isArray(v) && v.every((x) => typeof x === "number")) v.forEach((_, i) => out.push({ p, ptr: `${ptr}/${i}` }));
    else if (v === undefined && p.type === "number or spectral") out.push({ p, ptr });
  }
  return out;
}

/// The value a number has in the recipe, else its registry default (null when it has none).
function valueOf(ptr, p) {
  const v = getAt(state.recipe, ptr);
  if (typeof v === "number") return v;
  const d = p && p.default !== null && p.default !== undefined ? parseNumber(p.default) : NaN;
  return isFinite(d) ? d : null;
}

/// Bounds from the registry's range: the whole range when both ends are finite; an open end is moved in by
/// a millionth of the span; a range open above reaches ten times the value (at least 1).
function rangeOf(ptr, p) {
  const v = valueOf(ptr, p);
  const r = p && p.range ? p.range : { lo: null, hi: null, lo_closed: false, hi_closed: false };
  let lo = r.lo !== null ? r.lo : v !== null ? Math.min(0, v) - 10 * Math.abs(v || 1) : -1;
  let hi = r.hi !== null ? r.hi : Math.max(10 * Math.abs(v || 0), 1, lo + 1);
  const span = hi - lo;
  if (r.lo !== null && !r.lo_closed) lo += span * 1e-6;
  if (r.hi !== null && !r.hi_closed) hi -= span * 1e-6;
  return [Number(lo.toPrecision(6)), Number(hi.toPrecision(6))];
}

function optionText(ptr, p) {
  const v = getAt(state.recipe, ptr);
  const unit = p.unit ? ` (${p.unit})` : "";
  return label(ptr, state.recipe) + unit + (v === undefined ? `, not set (default ${p.default})` : "");
}

/// The recipe sent for a sweep or a fit of `ptr`: the editor's, with the number set when it is not (a fit
/// starts from the recipe's value, which must lie strictly inside the bounds: else the middle of them).
function recipeWith(ptr, p, lo, hi) {
  const r = JSON.parse(JSON.stringify(state.recipe));
  let v = valueOf(ptr, p);
  let note = "";
  if (lo !== undefined && !(v > lo && v < hi)) {
    v = Number(((lo + hi) / 2).toPrecision(6));
    note = `${label(ptr, state.recipe)} started from ${v}, the middle of its bounds (the recipe's value is not inside them)`;
  }
  if (getAt(r, ptr) === undefined || lo !== undefined) setAt(r, ptr, v);
  return { recipe: r, note };
}

// ---- sweep ------------------------------------------------------------------------------------------

function buildSweepChoices() {
  const sel = $("sweep-path");
  const keep = sel.value;
  sel.replaceChildren();
  for (const { p, ptr } of numberFields()) sel.append(el("option", { value: ptr, text: optionText(ptr, p) }));
  if ([...sel.options].some((o) => o.value === keep)) sel.value = keep;
  else sweepRange();
}

function sweepRange() {
  const ptr = $("sweep-path").value;
  if (!ptr) return;
  const [lo, hi] = rangeOf(ptr, entryOf(ptr, state.recipe.model));
  $("sweep-lo").value = lo;
  $("sweep-hi").value = hi;
}

async function sweep() {
  const ptr = $("sweep-path").value;
  const lo = parseNumber($("sweep-lo").value), hi = parseNumber($("sweep-hi").value), n = Math.round(parseNumber($("sweep-n").value));
  $("sweep-error").textContent = "";
  $("sweep-download").disabled = true;
  $("sweep-csv").disabled = true;
  if (!ptr) {
    $("sweep-error").textContent = "the recipe has no number to vary";
    return;
  }
  if (!isFinite(lo) || !isFinite(hi) || !isFinite(n)) {
    $("sweep-error").textContent = "from, to and points must be numbers";
    return;
  }
  const p = entryOf(ptr, state.recipe.model);
  // The colour geometries the library refused for this recipe (the readings say why) are not swept.
  const refused = state.doc && state.doc.refused ? state.doc.refused.geometries : [];
  const geos = chosenGeometries().filter((id) => !refused.includes(id));
  const body = { recipe: recipeWith(ptr, p).recipe, vary: [`${ptr}=${lo}..${hi}:${n}`], geometries: geos, ...conditions() };
  const thead = $("sweep-rows").querySelector("thead"), tbody = $("sweep-rows").querySelector("tbody");
  tbody.replaceChildren();
  thead.replaceChildren();
  $("sweep-charts").replaceChildren();
  $("sweep-go").disabled = true;
  state.sweepText = "";
  state.sweepRows = [];
  state.sweepPtr = ptr;
  const what = label(ptr, state.recipe) + (p && p.unit ? ` (${p.unit})` : "");
  try {
    const r = await post("/api/sweep", body);
    const total = Number(r.headers.get("x-points")) || n;
    $("sweep-progress").max = total;
    $("sweep-progress").value = 0;
    const reader = r.body.getReader();
    const dec = new TextDecoder();
    let buf = "", done = 0, header = false;
    for (;;) {
      const { value, done: end } = await reader.read();
      if (end) break;
      buf += dec.decode(value, { stream: true });
      let k;
      while ((k = buf.indexOf("\n")) >= 0) {
        const line = buf.slice(0, k);
        buf = buf.slice(k + 1);
        if (!line.trim()) continue;
        state.sweepText += line + "\n";
        const row = JSON.parse(line);
        if (row.error) throw new Error(row.error);
        state.sweepRows.push(row);
        if (!header && row.readings) {
          header = true;
          const tr = el("tr", {}, el("th", { text: what }));
          for (const rd of row.readings) tr.append(el("th", { class: "num", text: `${geometryOf(rd.geometry).title}: ${rd.name} (${rd.unit})` }));
          thead.append(tr);
        }
        const tr = el("tr", {}, el("td", { class: "num", text: String(row.parameters[ptr]) }));
        if (row.problem) tr.append(el("td", { class: "warn", text: row.problem }));
        for (const rd of row.readings || []) tr.append(el("td", { class: "num", text: display(rd.value, rd.unit) }));
        tbody.append(tr);
        done += 1;
        $("sweep-progress").value = done;
        $("sweep-count").textContent = `${done} / ${total} points`;
      }
    }
    $("sweep-download").disabled = false;
    $("sweep-csv").disabled = false;
    drawSweep(ptr, what);
  } catch (e) {
    $("sweep-error").textContent = e.message;
  } finally {
    $("sweep-go").disabled = false;
  }
}

/// The sweep as CSV: the varied number, then each reading's value and numerical error estimate.
function sweepCsv() {
  const rows = state.sweepRows, ptr = state.sweepPtr;
  const first = rows.find((r) => r.readings);
  if (!first) return "";
  const q = (s) => (/[",\n]/.test(s) ? `"${s.replace(/"/g, '""')}"` : s);
  const head = [ptr];
  // A colour reading's header says its conditions beside its unit, as the command line's sweep CSV does.
  const said = (rd) => [rd.unit, rd.illuminant && conditionsText(rd)].filter((x) => x).join(", ");
  for (const rd of first.readings) head.push(`${rd.geometry}/${rd.name} (${said(rd)})`, `${rd.geometry}/${rd.name} error estimate`);
  head.push("problem");
  const lines = [head.map(q).join(",")];
  for (const r of rows) {
    const cells = [String(r.parameters[ptr])];
    for (const rd of first.readings) {
      const x = (r.readings || []).find((y) => y.geometry === rd.geometry && y.name === rd.name);
      cells.push(x && x.value !== null ? String(x.value) : "", x && x.error_estimate !== null && x.value !== null ? String(x.error_estimate) : "");
    }
    cells.push(r.problem || "");
    lines.push(cells.map(q).join(","));
  }
  return lines.join("\n") + "\n";
}

const SVG = "http://www.w3.org/2000/svg";
function svg(tag, attrs, ...children) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, k === "text" ? "" : v);
  if (attrs && attrs.text !== undefined) e.textContent = attrs.text;
  for (const c of children) e.append(c);
  return e;
}

function ticks(lo, hi, n) {
  const span = hi - lo || Math.abs(hi) || 1;
  const step0 = span / n, mag = 10 ** Math.floor(Math.log10(step0));
  const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= step0);
  const out = [];
  for (let t = Math.ceil(lo / step) * step; t <= hi + step * 1e-9; t += step) out.push(Number(t.toPrecision(12)));
  return out;
}

const COLOURS = ["#1f5fbf", "#b3261e", "#116329", "#8a5a00", "#6f42c1", "#0a7d8c", "#c2185b", "#57606a"];

/// The axis a reading is drawn on: its unit (GU, HU, HU(log), DOI, ° of the hue angle); colour's unitless
/// coordinates on two axes of their own, CIELAB (L*, a*, b*, C*) and X, Y, Z (as the command line's pictures,
/// `report::pictures::charts::axis_of`).
function axisOf(unit, name) {
  if (unit !== "") return unit;
  return ["X", "Y", "Z"].includes(name) ? "X, Y, Z" : "L*, a*, b*, C*";
}

/// One chart per axis (GU, HU, DOI, …, CIELAB, X Y Z): the readings on it against the varied number.
function drawSweep(ptr, what) {
  const rows = state.sweepRows.filter((r) => r.readings);
  const box = $("sweep-charts");
  box.replaceChildren();
  if (!rows.length) return;
  const axes = [...new Set(rows[0].readings.map((r) => axisOf(r.unit, r.name)))];
  for (const axis of axes) {
    const unit = rows[0].readings.find((r) => axisOf(r.unit, r.name) === axis).unit;
    const series = rows[0].readings.filter((r) => axisOf(r.unit, r.name) === axis).map((r) => ({ geometry: r.geometry, name: r.name, pts: [] }));
    for (const row of rows) {
      for (const s of series) {
        const x = row.readings.find((y) => y.geometry === s.geometry && y.name === s.name);
        if (x && x.value !== null) s.pts.push([row.parameters[ptr], x.value]);
      }
    }
    const xs = series.flatMap((s) => s.pts.map((p) => p[0])), ys = series.flatMap((s) => s.pts.map((p) => p[1]));
    if (!xs.length) continue;
    let [x0, x1] = [Math.min(...xs), Math.max(...xs)], [y0, y1] = [Math.min(...ys), Math.max(...ys)];
    if (y1 - y0 < stepOf(unit)) [y0, y1] = [y0 - stepOf(unit), y1 + stepOf(unit)];
    if (x1 === x0) [x0, x1] = [x0 - 1, x1 + 1];
    const W = 520, H = 260, L = 58, R = 12, T = 24, B = 40;
    const sx = (x) => L + ((x - x0) / (x1 - x0)) * (W - L - R), sy = (y) => H - B - ((y - y0) / (y1 - y0)) * (H - T - B);
    const colour = unit === "" ? `colour: ${axis} (no unit)` : null;
    const g = svg("svg", { viewBox: `0 0 ${W} ${H}`, width: W, height: H, role: "img", class: "chart", "data-unit": axis });
    g.append(svg("title", { text: `${colour || axis} against ${what}` }));
    g.append(svg("rect", { x: L, y: T, width: W - L - R, height: H - T - B, fill: "none", stroke: "#d0d7de" }));
    for (const t of ticks(x0, x1, 6)) {
      g.append(svg("line", { x1: sx(t), x2: sx(t), y1: H - B, y2: H - B + 4, stroke: "#57606a" }));
      g.append(svg("text", { x: sx(t), y: H - B + 16, "text-anchor": "middle", "font-size": 11, text: String(t) }));
    }
    for (const t of ticks(y0, y1, 5)) {
      g.append(svg("line", { x1: L - 4, x2: W - R, y1: sy(t), y2: sy(t), stroke: "#eaeef2" }));
      g.append(svg("text", { x: L - 6, y: sy(t) + 4, "text-anchor": "end", "font-size": 11, text: String(t) }));
    }
    g.append(svg("text", { x: (L + W - R) / 2, y: H - 6, "text-anchor": "middle", "font-size": 12, text: what }));
    g.append(svg("text", { x: 14, y: (T + H - B) / 2, "text-anchor": "middle", "font-size": 12, transform: `rotate(-90 14 ${(T + H - B) / 2})`, text: colour || axis }));
    series.forEach((s, i) => {
      const c = COLOURS[i % COLOURS.length];
      g.append(svg("polyline", { points: s.pts.map(([x, y]) => `${sx(x).toFixed(1)},${sy(y).toFixed(1)}`).join(" "), fill: "none", stroke: c, "stroke-width": 2, class: "series" }));
      for (const [x, y] of s.pts) g.append(svg("circle", { cx: sx(x).toFixed(1), cy: sy(y).toFixed(1), r: 2.5, fill: c }));
    });
    const cap = el("figcaption", { class: "legend" });
    series.forEach((s, i) => {
      const key = el("span", { class: "key" });
      key.style.background = COLOURS[i % COLOURS.length];
      cap.append(el("span", { class: "item" }, key, `${geometryOf(s.geometry).title}: ${s.name}`));
    });
    box.append(el("figure", {}, g, cap));
  }
}

// ---- compare ----------------------------------------------------------------------------------------

function toBase64(buf) {
  const bytes = new Uint8Array(buf);
  let s = "";
  for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return btoa(s);
}

async function readSheet() {
  const f = $("sheet").files[0];
  if (!f) return null;
  state.sheet = { name: f.name, base64: toBase64(await f.arrayBuffer()) };
  return state.sheet;
}

function compareBody(format) {
  const b = { recipe: state.recipe, sheet: state.sheet, k: $("cmp-k").value.trim() ? parseNumber($("cmp-k").value) : 2, ...conditions(), format };
  const t = $("cmp-tol").value.trim();
  if (t !== "") b.tolerance = parseNumber(t);
  return b;
}

async function compare() {
  $("compare-error").textContent = "";
  for (const b of ["dl-json", "dl-csv", "dl-junit"]) $(b).disabled = true;
  const tbody = $("verdicts").querySelector("tbody");
  tbody.replaceChildren();
  $("compare-summary").textContent = "";
  try {
    if (!(await readSheet())) throw new Error("choose a sheet first");
    status("comparing…");
    const doc = await (await post("/api/compare", compareBody("json"))).json();
    state.compareDoc = doc;
    for (const c of doc.comparisons) {
      const cls = c.verdict === "ok" ? "ok" : c.verdict === "OUTSIDE" ? "bad" : "warn";
      tbody.append(el("tr", {},
        el("td", { text: c.sample }), el("td", { text: geometryOf(c.geometry).title, title: c.geometry }), el("td", { text: c.reading }),
        el("td", { class: "num", text: String(c.n) }), el("td", { class: "num", text: shown(c.mean, 1e-3) }),
        el("td", { class: "num", text: shown(c.predicted, 1e-3) }), el("td", { class: "num", text: shown(c.difference, 1e-3) }),
        el("td", { class: "num", text: c.allowance ? shown(c.allowance.total, 1e-3) : "—" }),
        el("td", { class: "verdict " + cls, text: c.verdict, title: c.unchecked || c.reason || "" })));
    }
    const s = doc.summary || {};
    $("compare-summary").textContent = Object.entries(s).map(([k, v]) => `${k}: ${typeof v === "object" ? JSON.stringify(v) : v}`).join("; ");
    for (const b of ["dl-json", "dl-csv", "dl-junit"]) $(b).disabled = false;
    status(`compared ${doc.comparisons.length} reading(s) of ${state.sheet.name}`);
  } catch (e) {
    $("compare-error").textContent = e.message;
    status("the comparison failed");
  }
}

async function compareDownload(format) {
  try {
    const r = await post("/api/compare", compareBody(format));
    const ext = { json: "json", csv: "csv", junit: "xml" }[format];
    download(`compare.${ext}`, await r.text(), r.headers.get("content-type") || "text/plain");
  } catch (e) {
    $("compare-error").textContent = e.message;
  }
}

// ---- fit --------------------------------------------------------------------------------------------

/// The unit of a reading the readings table shows (null: not shown there).
function unitOf(geometry, name) {
  const r = state.doc && state.doc.readings.find((x) => x.geometry === geometry && x.name === name);
  return r ? r.unit : null;
}

function buildFitChoices() {
  const box = $("fit-free");
  const was = new Map([...box.querySelectorAll(".fit-row")].map((r) => [r.querySelector("input[type=checkbox]").value, r]));
  box.replaceChildren(el("legend", { text: "Free parameters and their bounds (the registry's allowed range)" }));
  numberFields().forEach(({ p, ptr }, i) => {
    const [lo, hi] = rangeOf(ptr, p);
    const id = "fit-free-" + i;
    const c = el("input", { type: "checkbox", id, value: ptr });
    const old = was.get(ptr);
    c.checked = old ? old.querySelector("input[type=checkbox]").checked : false;
    const lab = optionText(ptr, p);
    const loI = numberInput({ value: old ? old.querySelector(".lo").value : lo, "aria-label": lab + " lower bound", class: "number lo" });
    const hiI = numberInput({ value: old ? old.querySelector(".hi").value : hi, "aria-label": lab + " upper bound", class: "number hi" });
    box.append(el("div", { class: "fit-row" }, c, el("label", { for: id, text: lab, title: ptr }), loI, el("span", { text: "to" }), hiI));
  });
}

async function fit() {
  $("fit-error").textContent = "";
  $("fit-verdict").textContent = "";
  $("fit-apply").disabled = true;
  const rows = [...$("fit-free").querySelectorAll(".fit-row")].filter((r) => r.querySelector("input[type=checkbox]").checked);
  const notes = [];
  let recipe = JSON.parse(JSON.stringify(state.recipe));
  const free = [];
  try {
    for (const r of rows) {
      const ptr = r.querySelector("input[type=checkbox]").value;
      const lo = parseNumber(r.querySelector(".lo").value), hi = parseNumber(r.querySelector(".hi").value);
      if (!isFinite(lo) || !isFinite(hi)) throw new Error(`${label(ptr, state.recipe)}: the bounds must be numbers`);
      const p = entryOf(ptr, state.recipe.model);
      const saved = state.recipe;
      state.recipe = recipe;
      const w = recipeWith(ptr, p, lo, hi);
      state.recipe = saved;
      recipe = w.recipe;
      if (w.note) notes.push(w.note);
      free.push(`${ptr}=${lo}..${hi}`);
    }
    const body = { recipe, free, ...conditions() };
    if ($("fit-use-sheet").checked) {
      if (!(await readSheet())) throw new Error("choose a sheet in the Compare tab first");
      body.sheet = state.sheet;
      if ($("fit-sample").value.trim()) body.sample = $("fit-sample").value.trim();
    } else {
      // A decimal comma between digits is a decimal point (`85,2±0,5`); the geometry ids have none.
      body.target = $("fit-targets").value.split("\n").map((s) => s.trim().replace(/(\d),(\d)/g, "$1.$2")).filter((s) => s);
    }
    status("fitting…");
    $("fit-go").disabled = true;
    const doc = await (await post("/api/fit", body)).json();
    const pb = $("fit-params").querySelector("tbody"), tb = $("fit-tgts").querySelector("tbody");
    pb.replaceChildren();
    tb.replaceChildren();
    for (const p of doc.parameters) {
      const v = el("td", { class: "num value", text: Number(p.value).toPrecision(4) });
      v.dataset.value = String(p.value);
      pb.append(el("tr", { "data-pointer": p.path }, el("td", { text: label(p.path, state.recipe), title: p.path }), v,
        el("td", { class: "num", text: p.std_error === null ? "undetermined" : Number(p.std_error).toPrecision(2) }),
        el("td", { text: `${p.lower} … ${p.upper}` }), el("td", { class: p.at_bound ? "warn" : "", text: p.at_bound ? "AT BOUND" : "" })));
    }
    for (const t of doc.targets) {
      const tr = el("tr", { "data-geometry": t.geometry, "data-name": t.name }, el("td", { text: `${geometryOf(t.geometry).title}: ${t.name}`, title: t.geometry }),
        el("td", { class: "num", text: String(t.measured) }),
        el("td", { class: "num", text: String(t.uncertainty) }), el("td", { class: "num predicted", text: unitOf(t.geometry, t.name) === null ? Number(t.predicted).toPrecision(4) : display(t.predicted, unitOf(t.geometry, t.name)) }),
        el("td", { class: "num", text: Number(t.residual).toPrecision(2) }));
      tr.querySelector(".predicted").dataset.value = String(t.predicted);
      tb.append(tr);
    }
    const ok = doc.converged && doc.reproduces && doc.identifiable && !doc.stationary && !doc.parameters.some((p) => p.at_bound);
    $("fit-verdict").textContent = (ok ? "The fit is to be trusted" : "The fit is NOT to be trusted") +
      `: converged ${doc.converged}, reproduces the readings ${doc.reproduces}, identifiable ${doc.identifiable}; χ² = ${Number(doc.chi2).toPrecision(4)} for ${doc.dof} degree(s) of freedom; ${doc.evaluations} forward runs.`;
    $("fit-verdict").className = ok ? "ok" : "bad";
    $("fit-notes").replaceChildren(...[...notes, ...doc.verdict].map((v) => el("li", { text: v })));
    state.fitRecipe = doc.recipe;
    $("fit-apply").disabled = false;
    status("fit done");
  } catch (e) {
    $("fit-error").textContent = e.message;
    status("the fit failed");
  } finally {
    $("fit-go").disabled = false;
  }
}

// ---- plan -------------------------------------------------------------------------------------------

async function plan() {
  $("plan-error").textContent = "";
  try {
    const doc = await (await post("/api/explain", { recipe: state.recipe, geometries: chosenGeometries(), ...conditions() })).json();
    $("plan").textContent = doc.plan;
  } catch (e) {
    $("plan-error").textContent = e.message;
  }
}

// ---- tabs (WAI-ARIA: arrow keys move between tabs) --------------------------------------------------

function selectTab(tab) {
  for (const t of document.querySelectorAll("[role=tab]")) {
    const on = t === tab;
    t.setAttribute("aria-selected", String(on));
    t.tabIndex = on ? 0 : -1;
    $(t.getAttribute("aria-controls")).hidden = !on;
  }
  tab.focus();
  if (tab.id === "tab-pictures" && $("picture-live").checked) pictureSoon();
}

function setupTabs() {
  const tabs = [...document.querySelectorAll("[role=tab]")];
  tabs.forEach((t, i) => {
    t.addEventListener("click", () => selectTab(t));
    t.addEventListener("keydown", (e) => {
      const k = { ArrowRight: 1, ArrowLeft: -1 }[e.key];
      if (k) {
        e.preventDefault();
        selectTab(tabs[(i + k + tabs.length) % tabs.length]);
      } else if (e.key === "Home") selectTab(tabs[0]);
      else if (e.key === "End") selectTab(tabs[tabs.length - 1]);
    });
  });
}

// ---- start ----------------------------------------------------------------------------------------

async function start() {
  $("params").addEventListener("submit", (e) => e.preventDefault());
  const [reg, geos, fix, tables] = await Promise.all(["/api/registry", "/api/geometries", "/api/fixtures", "/api/tables"].map((p) => fetch(p).then((r) => r.json())));
  state.registry = reg;
  state.tables = tables;
  state.geometries = geos.geometries;
  for (const m of reg.models) $("model").append(el("option", { value: m, text: m }));
  buildConditions(reg.colour_conditions);
  const box = $("geometries");
  geos.geometries.forEach((g, i) => {
    const c = el("input", { type: "checkbox", id: "geo-" + i, value: g.id });
    c.checked = g.default;
    c.addEventListener("change", () => {
      recipeChanged();
      remeasurePinned();
    });
    box.append(el("div", { class: "geo" }, c, el("label", { for: "geo-" + i, text: `${g.title}`, title: g.line })));
  });
  state.fixtures = fix.fixtures;
  for (const f of fix.fixtures) $("fixture").append(el("option", { value: f.name, text: f.name }));
  $("fixture").addEventListener("change", () => {
    const f = state.fixtures.find((x) => x.name === $("fixture").value);
    if (unsaved() && !confirm("Your edits are not saved. Start from the shipped recipe anyway?")) return;
    setRecipe(JSON.parse(f.recipe));
  });
  $("model").addEventListener("change", modelChanged);
  $("raw").addEventListener("input", rawChanged);
  $("save-file").addEventListener("click", saveFile);
  $("open-file").addEventListener("change", openFile);
  $("save-browser").addEventListener("click", saveBrowser);
  $("saved-list").addEventListener("change", loadBrowser);
  $("pin").addEventListener("click", pin);
  $("unpin").addEventListener("click", unpin);
  $("picture-go").addEventListener("click", picture);
  $("picture-kind").addEventListener("change", picture);
  $("sweep-path").addEventListener("change", sweepRange);
  $("sweep-go").addEventListener("click", sweep);
  $("sweep-download").addEventListener("click", () => download("sweep.jsonl", state.sweepText, "application/x-ndjson"));
  $("sweep-csv").addEventListener("click", () => download("sweep.csv", sweepCsv(), "text/csv"));
  $("compare-go").addEventListener("click", compare);
  $("sheet").addEventListener("change", compare);
  $("dl-json").addEventListener("click", () => compareDownload("json"));
  $("dl-csv").addEventListener("click", () => compareDownload("csv"));
  $("dl-junit").addEventListener("click", () => compareDownload("junit"));
  $("fit-go").addEventListener("click", fit);
  $("fit-apply").addEventListener("click", () => state.fitRecipe && setRecipe(state.fitRecipe, false));
  $("plan-go").addEventListener("click", plan);
  // A reload or a closed tab would discard edits not saved: the browser asks first (the draft is kept too).
  window.addEventListener("beforeunload", (e) => {
    if (!unsaved()) return;
    e.preventDefault();
    e.returnValue = "";
  });
  setupTabs();
  setHeaders();
  listSaved();
  let draft = null;
  try {
    draft = JSON.parse(localStorage.getItem(DRAFT) || "null");
  } catch (_) {
    draft = null;
  }
  if (draft && draft.recipe && typeof draft.recipe === "object") {
    state.savedText = "";
    setRecipe(draft.recipe, false);
    status(`restored the edits not saved from ${draft.at} (this browser's draft)`);
  } else setRecipe(JSON.parse(fix.fixtures[0].recipe));
}

start().catch((e) => status("the page could not start: " + e.message));
