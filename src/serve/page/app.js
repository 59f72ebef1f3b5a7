// The page of `glossmeter serve` (docs/serve.md §The page). Plain JavaScript, no library: the recipe editor
// is generated from /api/registry; every number shown comes from the server's documents, which are the
// command line's (`measure`, `sweep`, `compare`, `fit`); pictures are the SVG the library draws.
"use strict";

const $ = (id) => document.getElementById(id);
const state = {
  registry: null, // {models, parameters}
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

// ---- the recipe editor ------------------------------------------------------------------------------

/// The fields the editor shows for the recipe: the registry entries of its model whose parent object is in
/// the recipe (optional blocks absent from it are added in the raw JSON).
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
      input = el("input", {
        id, type: "number", step: "any",
        min: p.range && p.range.lo !== null && p.range.lo_closed ? p.range.lo : null,
        max: p.range && p.range.hi !== null && p.range.hi_closed ? p.range.hi : null,
        placeholder: p.required ? "required" : `default ${p.default}`,
      });
      input.value = typeof v === "number" ? String(v) : "";
    } else {
      // Colours, spectra, arrays, indices, text: the JSON of the value (text fields: the string).
      const text = p.numeric || typeof v !== "string" ? (v === undefined ? "" : JSON.stringify(v)) : v;
      input = el("input", { id, type: "text", placeholder: p.required ? "required" : `default ${p.default}` });
      input.value = text;
    }
    input.dataset.pointer = ptr;
    const unit = p.unit ? ` (${p.unit})` : "";
    const range = p.range ? ` ${p.range.text}` : "";
    const help = el("span", { class: "doc", id: id + "-doc", text: `${p.description}; ${p.type}${range}` });
    input.setAttribute("aria-describedby", id + "-doc");
    input.title = `${ptr}: ${p.description}`;
    form.append(el("div", { class: "field" }, el("label", { for: id, text: ptr + unit }), input, help));
    input.addEventListener(input.tagName === "SELECT" ? "change" : "input", () => fieldChanged(input, p));
  }
  buildSweepChoices();
  buildFitChoices();
}

function fieldChanged(input, p) {
  const ptr = input.dataset.pointer;
  const t = input.value.trim();
  let value;
  input.classList.remove("bad");
  if (t === "") value = undefined;
  else if (p.number) {
    value = Number(t);
    if (!isFinite(value)) {
      input.classList.add("bad");
      return;
    }
  } else if (p.type === "boolean") value = t === "true";
  else if (p.choices) value = t;
  else if (p.numeric) {
    try {
      value = JSON.parse(t);
    } catch (_) {
      input.classList.add("bad");
      return;
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

function setRecipe(r) {
  state.recipe = r;
  $("model").value = r.model || "";
  writeRaw();
  buildForm();
  recipeChanged();
}

function modelChanged() {
  const model = $("model").value;
  const old = state.recipe;
  const r = { model };
  for (const k of ["name", "description", "provenance", "notes"]) if (k in old) r[k] = old[k];
  // Keep the top-level fields the new model also has.
  for (const p of state.registry.parameters) {
    if (!p.models.includes(model) || p.pointer.split("/").length !== 2 || p.pointer === "/model") continue;
    const v = getAt(old, p.pointer);
    if (v !== undefined) setAt(r, p.pointer, v);
  }
  setRecipe(r);
}

// ---- readings ---------------------------------------------------------------------------------------

function chosenGeometries() {
  return [...document.querySelectorAll("#geometries input:checked")].map((i) => i.value);
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
}

async function measure() {
  const seq = ++state.measureSeq;
  if (state.measureAbort) state.measureAbort.abort();
  const ctl = new AbortController();
  state.measureAbort = ctl;
  markStale("computing…");
  status("measuring…");
  try {
    const r = await post("/api/measure", { recipe: state.recipe, geometries: chosenGeometries() }, ctl.signal);
    const doc = await r.json();
    if (seq !== state.measureSeq) return; // a newer request is under way: never show this one as current
    showReadings(doc);
    $("measure-error").textContent = "";
    status(`${doc.material.name}: ${doc.readings.length} reading(s), ${doc.evaluations} evaluations`);
  } catch (e) {
    if (isAbort(e) || seq !== state.measureSeq) return;
    if (e.status === 503) {
      markStale("server busy, retrying…");
      setTimeout(() => seq === state.measureSeq && measure(), 1000);
      return;
    }
    $("measure-error").textContent = e.message;
    $("readings").querySelector("tbody").replaceChildren();
    $("readings").classList.remove("stale");
    $("readings").setAttribute("aria-busy", "false");
    $("readings-state").textContent = "no readings";
    status("the recipe has an error");
  }
}

function showReadings(doc) {
  const body = $("readings").querySelector("tbody");
  body.replaceChildren();
  for (const r of doc.readings) {
    const v = el("td", { class: "num value", text: shown(r.value, r.error_estimate) });
    v.dataset.value = r.value === null ? "" : String(r.value);
    v.title = r.value === null ? "no value" : String(r.value);
    body.append(
      el("tr", { "data-geometry": r.geometry, "data-name": r.name },
        el("td", { text: r.geometry }),
        el("td", { text: r.name }),
        v,
        el("td", { class: "num", text: r.value === null ? "—" : r.error_estimate.toExponential(1) }),
        el("td", { text: r.unit }),
        el("td", { class: r.converged ? "" : "warn", text: r.converged ? "yes" : "NO" }),
        el("td", { class: "num", text: String(r.evaluations) }),
        el("td", { class: "note", text: r.note || r.problem || "" })),
    );
  }
  $("readings").classList.remove("stale");
  $("readings").setAttribute("aria-busy", "false");
  $("readings-state").textContent = "current";
}

// ---- pictures ---------------------------------------------------------------------------------------

const pictureSoon = debounce(picture, 600);

async function picture() {
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

// ---- sweep ------------------------------------------------------------------------------------------

function numberFields() {
  return fieldsOf(state.recipe).filter(({ p, ptr }) => p.number && typeof getAt(state.recipe, ptr) === "number");
}

function buildSweepChoices() {
  const sel = $("sweep-path");
  const keep = sel.value;
  sel.replaceChildren();
  for (const { p, ptr } of numberFields()) sel.append(el("option", { value: ptr, text: ptr + (p.unit ? ` (${p.unit})` : "") }));
  if ([...sel.options].some((o) => o.value === keep)) sel.value = keep;
  sweepRange();
}

function rangeAround(ptr) {
  const p = state.registry.parameters.find((q) => q.pointer === ptr.replace(/\/\d+(?=\/|$)/g, "/*"));
  const v = getAt(state.recipe, ptr);
  let lo = v * 0.5, hi = v === 0 ? 1 : v * 1.5;
  if (lo > hi) [lo, hi] = [hi, lo];
  if (p && p.range) {
    if (p.range.lo !== null) lo = Math.max(lo, p.range.lo_closed ? p.range.lo : p.range.lo + Math.abs(v) * 1e-3);
    if (p.range.hi !== null) hi = Math.min(hi, p.range.hi_closed ? p.range.hi : p.range.hi - Math.abs(v) * 1e-3);
  }
  return [Number(lo.toPrecision(4)), Number(hi.toPrecision(4))];
}

function sweepRange() {
  const ptr = $("sweep-path").value;
  if (!ptr) return;
  const [lo, hi] = rangeAround(ptr);
  $("sweep-lo").value = lo;
  $("sweep-hi").value = hi;
}

async function sweep() {
  const ptr = $("sweep-path").value;
  const lo = Number($("sweep-lo").value), hi = Number($("sweep-hi").value), n = Math.round(Number($("sweep-n").value));
  $("sweep-error").textContent = "";
  $("sweep-download").disabled = true;
  if (!ptr) {
    $("sweep-error").textContent = "the recipe has no number to vary";
    return;
  }
  const geos = chosenGeometries();
  const body = { recipe: state.recipe, vary: [`${ptr}=${lo}..${hi}:${n}`], geometries: geos };
  const thead = $("sweep-rows").querySelector("thead"), tbody = $("sweep-rows").querySelector("tbody");
  tbody.replaceChildren();
  thead.replaceChildren();
  $("sweep-go").disabled = true;
  $("sweep-picture").classList.add("stale");
  state.sweepText = "";
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
        if (!header) {
          header = true;
          const tr = el("tr", {}, el("th", { text: ptr }));
          for (const rd of row.readings || []) tr.append(el("th", { class: "num", text: `${rd.geometry} ${rd.name} (${rd.unit})` }));
          thead.append(tr);
        }
        const tr = el("tr", {}, el("td", { class: "num", text: String(row.parameters[ptr]) }));
        if (row.problem) tr.append(el("td", { class: "warn", text: row.problem }));
        for (const rd of row.readings || []) tr.append(el("td", { class: "num", text: shown(rd.value, rd.error_estimate) }));
        tbody.append(tr);
        done += 1;
        $("sweep-progress").value = done;
        $("sweep-count").textContent = `${done} / ${total} points`;
      }
    }
    $("sweep-download").disabled = false;
    const p = await post("/api/plot", { recipe: state.recipe, kind: "gloss-vs-parameter", vary: `${ptr}=${lo}..${hi}`, points: Math.min(n, 41), geometries: geos });
    showSvg($("sweep-picture"), await p.text());
    $("sweep-picture").classList.remove("stale");
  } catch (e) {
    $("sweep-error").textContent = e.message;
  } finally {
    $("sweep-go").disabled = false;
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
  const b = { recipe: state.recipe, sheet: state.sheet, k: Number($("cmp-k").value || 2), format };
  const t = $("cmp-tol").value.trim();
  if (t !== "") b.tolerance = Number(t);
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
        el("td", { text: c.sample }), el("td", { text: c.geometry }), el("td", { text: c.reading }),
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

function buildFitChoices() {
  const box = $("fit-free");
  const was = new Map([...box.querySelectorAll("input[type=checkbox]")].map((c) => [c.value, c.checked]));
  box.replaceChildren(el("legend", { text: "Free parameters and their bounds" }));
  numberFields().forEach(({ ptr }, i) => {
    const [lo, hi] = rangeAround(ptr);
    const id = "fit-free-" + i;
    const c = el("input", { type: "checkbox", id, value: ptr });
    c.checked = was.get(ptr) || false;
    box.append(el("div", { class: "fit-row" }, c, el("label", { for: id, text: ptr }),
      el("input", { type: "number", step: "any", value: lo, "aria-label": ptr + " lower bound", class: "lo" }),
      el("input", { type: "number", step: "any", value: hi, "aria-label": ptr + " upper bound", class: "hi" })));
  });
}

async function fit() {
  $("fit-error").textContent = "";
  $("fit-verdict").textContent = "";
  $("fit-apply").disabled = true;
  const free = [...$("fit-free").querySelectorAll(".fit-row")]
    .filter((r) => r.querySelector("input[type=checkbox]").checked)
    .map((r) => `${r.querySelector("input[type=checkbox]").value}=${r.querySelector(".lo").value}..${r.querySelector(".hi").value}`);
  const body = { recipe: state.recipe, free };
  try {
    if ($("fit-use-sheet").checked) {
      if (!(await readSheet())) throw new Error("choose a sheet in the Compare tab first");
      body.sheet = state.sheet;
      if ($("fit-sample").value.trim()) body.sample = $("fit-sample").value.trim();
    } else {
      body.target = $("fit-targets").value.split("\n").map((s) => s.trim()).filter((s) => s);
    }
    status("fitting…");
    $("fit-go").disabled = true;
    const doc = await (await post("/api/fit", body)).json();
    const pb = $("fit-params").querySelector("tbody"), tb = $("fit-tgts").querySelector("tbody");
    pb.replaceChildren();
    tb.replaceChildren();
    for (const p of doc.parameters) {
      pb.append(el("tr", {}, el("td", { text: p.path }), el("td", { class: "num", text: String(p.value) }),
        el("td", { class: "num", text: p.std_error === null ? "undetermined" : p.std_error.toExponential(3) }),
        el("td", { text: `${p.lower} … ${p.upper}` }), el("td", { class: p.at_bound ? "warn" : "", text: p.at_bound ? "AT BOUND" : "" })));
    }
    for (const t of doc.targets) {
      tb.append(el("tr", {}, el("td", { text: `${t.geometry}/${t.name}` }), el("td", { class: "num", text: String(t.measured) }),
        el("td", { class: "num", text: String(t.uncertainty) }), el("td", { class: "num", text: shown(t.predicted, 1e-4) }),
        el("td", { class: "num", text: Number(t.residual).toExponential(3) })));
    }
    const ok = doc.converged && doc.reproduces && doc.identifiable && !doc.stationary && !doc.parameters.some((p) => p.at_bound);
    $("fit-verdict").textContent = (ok ? "The fit is to be trusted" : "The fit is NOT to be trusted") +
      `: converged ${doc.converged}, reproduces the readings ${doc.reproduces}, identifiable ${doc.identifiable}; χ² = ${Number(doc.chi2).toPrecision(4)} for ${doc.dof} degree(s) of freedom; ${doc.evaluations} forward runs.`;
    $("fit-verdict").className = ok ? "ok" : "bad";
    $("fit-notes").replaceChildren(...doc.verdict.map((v) => el("li", { text: v })));
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
    const doc = await (await post("/api/explain", { recipe: state.recipe, geometries: chosenGeometries() })).json();
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

// ---- start ------------------------------------------------------------------------------------------

async function start() {
  $("params").addEventListener("submit", (e) => e.preventDefault());
  const [reg, geos, fix] = await Promise.all(["/api/registry", "/api/geometries", "/api/fixtures"].map((p) => fetch(p).then((r) => r.json())));
  state.registry = reg;
  state.geometries = geos.geometries;
  for (const m of reg.models) $("model").append(el("option", { value: m, text: m }));
  const box = $("geometries");
  geos.geometries.forEach((g, i) => {
    const c = el("input", { type: "checkbox", id: "geo-" + i, value: g.id });
    c.checked = g.default;
    c.addEventListener("change", recipeChanged);
    box.append(el("div", { class: "geo" }, c, el("label", { for: "geo-" + i, text: g.line })));
  });
  state.fixtures = fix.fixtures;
  for (const f of fix.fixtures) $("fixture").append(el("option", { value: f.name, text: f.name }));
  $("fixture").addEventListener("change", () => {
    const f = state.fixtures.find((x) => x.name === $("fixture").value);
    setRecipe(JSON.parse(f.recipe));
  });
  $("model").addEventListener("change", modelChanged);
  $("raw").addEventListener("input", rawChanged);
  $("picture-go").addEventListener("click", picture);
  $("picture-kind").addEventListener("change", picture);
  $("sweep-path").addEventListener("change", sweepRange);
  $("sweep-go").addEventListener("click", sweep);
  $("sweep-download").addEventListener("click", () => download("sweep.jsonl", state.sweepText, "application/x-ndjson"));
  $("compare-go").addEventListener("click", compare);
  $("sheet").addEventListener("change", compare);
  $("dl-json").addEventListener("click", () => compareDownload("json"));
  $("dl-csv").addEventListener("click", () => compareDownload("csv"));
  $("dl-junit").addEventListener("click", () => compareDownload("junit"));
  $("fit-go").addEventListener("click", fit);
  $("fit-apply").addEventListener("click", () => state.fitRecipe && setRecipe(state.fitRecipe));
  $("plan-go").addEventListener("click", plan);
  setupTabs();
  setRecipe(JSON.parse(fix.fixtures[0].recipe));
}

start().catch((e) => status("the page could not start: " + e.message));
