// The page of `portalsim serve`: every change posts the settings to /api/render and
// redraws the three sensors; errors from the server are shown as they come.
"use strict";
const $ = (id) => document.getElementById(id);
let cat = null;
let knobs = [];
let pending = 0;

function settings() {
  const objects = [];
  for (let r = 1; r <= cat.regions.length; ++r) objects.push($("region" + r).value);
  const s = {
    subject: Number($("subject").value), seed: $("seed").value, tier: $("tier").value,
    rule: $("rule").value.trim(), threat: $("threat").value, objects,
  };
  // Every knob as its flag takes it; an empty fidelity knob leaves the tier's value.
  for (const k of knobs) {
    const c = $("knob-" + k.key);
    const v = c.type === "checkbox" ? (c.checked ? "on" : "off") : c.value.trim();
    if (v !== "") s[k.key] = v;
  }
  return s;
}

// One control per knob of the registry (/api/knobs), by its kind: a checkbox for on/off,
// a list for a choice, a number field within the knob's range, text for WxH and A..B (and
// for a knob that may be drawn per scenario).
function knobControl(k) {
  let c;
  if ((k.fidelity && k.choices.length) || k.kind === "choice") {
    c = document.createElement("select");
    if (k.fidelity) option(c, "", "from the tier (" + k.default + ")");
    k.choices.forEach((v) => option(c, v));
    c.value = k.fidelity ? "" : k.default;
  } else if (k.kind === "on_off") {
    c = document.createElement("input");
    c.type = "checkbox";
    c.checked = k.default === "on";
  } else {
    c = document.createElement("input");
    if (k.drawable) {  // a number, or A..B drawn per scenario (Generate's data set varies it)
      c.type = "text";
      c.placeholder = k.min + " .. " + k.max + ", or A..B";
    } else if (k.kind === "integer" || k.kind === "number") {
      c.type = "number";
      c.min = k.min; c.max = k.max; c.step = k.kind === "integer" ? "1" : "any";
    }
    c.value = k.fidelity ? "" : k.default;
    if (k.fidelity) c.placeholder = "from the tier (" + k.default + ")";
  }
  c.id = "knob-" + k.key;
  c.title = k.help + " (" + k.flag + ": " + k.values + ")";
  c.addEventListener("change", render);
  const row = document.createElement("div");
  row.className = "row knob";
  const label = document.createElement("label");
  label.htmlFor = c.id;
  label.textContent = k.key.replaceAll("_", " ") + (k.unit ? " (" + k.unit + ")" : "");
  row.append(label, c);
  $(k.fidelity ? "knobs-fidelity" : "knobs-" + k.group).appendChild(row);
}

async function post(path, body) {
  const res = await fetch(path, { method: "POST", headers: { "Content-Type": "application/json" },
    body: JSON.stringify(body) });
  const data = await res.json().catch(() => ({ error: "HTTP " + res.status }));
  if (!res.ok) throw new Error(data.error || "HTTP " + res.status);
  return data;
}

function drawZones(metal) {
  $("zones").value = metal.join(",");
  for (let z = 0; z < metal.length; ++z) {
    const row = $("zone" + (z + 1));
    // The bar is the metal signal: empty at 200 (nothing), full at 0.
    row.querySelector(".bar div").style.width = ((200 - metal[z]) / 200 * 100) + "%";
    row.querySelector(".value").textContent = metal[z];
    row.classList.toggle("hit", metal[z] < 200);
    row.setAttribute("aria-label", "zone " + (z + 1) + ": " + metal[z]);
  }
}

async function render() {
  const ticket = ++pending;
  try {
    const out = await post("/api/render", settings());
    if (ticket !== pending) return;  // a newer change is on its way
    for (const v of cat.views) $(v.name).src = out[v.name];
    drawZones(out.metal);
    $("label").textContent = "Threat: " + (out.threat ? "yes" : "no");
    $("error").textContent = "";
    if ($("side-by-side").checked) await compare(ticket);
    document.body.dataset.rendered = String(ticket);
  } catch (e) {
    if (ticket === pending) $("error").textContent = e.message;
  }
}

// The same scenario and knobs under each model, in two columns.
async function compare(ticket) {
  for (const model of ["thesis", "physics"]) {
    const out = await post("/api/render", { ...settings(), model });
    if (ticket !== pending) return;
    for (const v of cat.views) $(model + "-" + v.name).src = out[v.name];
    $(model + "-zones").value = out.metal.join(",");
  }
}

function option(select, value, text) {
  const o = document.createElement("option");
  o.value = value; o.textContent = text ?? value;
  select.appendChild(o);
}

function regionChanged(r) {
  const v = $("region" + r).value;
  const b = $("hit" + r);
  b.classList.toggle("filled", v !== "none");
  b.setAttribute("aria-label", "region " + r + " " + cat.regions[r - 1].name + ": " + v);
  b.textContent = v === "none" ? r : r + " " + v;
  render();
}

// "MMW upper", "MMW back_upper (back)", "IR": what a view shows, for captions and alt text.
function viewTitle(v) {
  return v.camera.toUpperCase() + (v.name === v.camera ? "" : " " + v.name) + (v.side === "back" ? " (back)" : "");
}

// One figure per camera view of the catalogue, 300 pixels high at the view's aspect, and a
// small copy of each in both side-by-side columns.
function buildViews() {
  for (const v of cat.views) {
    const [w, h] = v.size;
    const fig = document.createElement("figure");
    const body = document.createElement("div");
    body.className = "body"; body.id = "body-" + v.name;
    body.style.width = 300 * w / h + "px";
    const img = document.createElement("img");
    img.id = v.name; img.alt = viewTitle(v) + " image";
    body.appendChild(img);
    const cap = document.createElement("figcaption");
    cap.textContent = viewTitle(v);
    fig.append(body, cap);
    $("views").appendChild(fig);
    for (const model of ["thesis", "physics"]) {
      const small = document.createElement("img");
      small.id = model + "-" + v.name; small.alt = viewTitle(v) + ", " + model + " model";
      small.style.width = 150 * w / h + "px";
      $(model + "-views").appendChild(small);
    }
  }
}

async function init() {
  cat = await (await fetch("/api/catalogue")).json();
  buildViews();
  knobs = await (await fetch("/api/knobs")).json();
  knobs.forEach(knobControl);
  cat.subjects.forEach((s, i) => {
    const note = cat.subject_notes[i];
    option($("subject"), i + 1, (i + 1) + " " + s + (note ? " (" + note + ")" : ""));
  });
  cat.tiers.forEach((t) => option($("tier"), t));
  $("tier").value = "standard";
  cat.objects.forEach((o) => option($("tool"), o));
  $("tool").value = cat.objects.find((o) => o.startsWith("gun")) ?? cat.objects[0];
  for (const reg of cat.regions) {
    const r = reg.id;
    const row = document.createElement("div");
    row.className = "row";
    const label = document.createElement("label");
    label.htmlFor = "region" + r; label.textContent = r + " " + reg.name;
    const sel = document.createElement("select");
    sel.id = "region" + r;
    option(sel, "none");
    cat.objects.forEach((o) => option(sel, o));
    sel.addEventListener("change", () => regionChanged(r));
    row.append(label, sel);
    $("regions").appendChild(row);
    // The clickable region on the body: a button, so it is focusable and has a name.
    const b = document.createElement("button");
    b.id = "hit" + r; b.className = "region"; b.type = "button";
    b.addEventListener("click", () => {
      sel.value = sel.value === $("tool").value ? "none" : $("tool").value;
      regionChanged(r);
    });
    $("body-" + reg.view).appendChild(b);
    b.textContent = r;
    b.setAttribute("aria-label", "region " + r + " " + reg.name + ": none");
  }
  placeHits();
  // The catalogue's zones, in the column of the panel each transmits from (A where unknown).
  for (const { id, panel } of cat.zones) {
    const row = document.createElement("div");
    row.className = "zone"; row.id = "zone" + id; row.setAttribute("role", "img");
    row.innerHTML = '<span class="name">' + id + '</span><div class="bar"><div></div></div><span class="value"></span>';
    $(panel === "b" ? "panel-b" : "panel-a").appendChild(row);
  }
  for (const id of ["subject", "seed", "tier", "rule", "threat"])
    $(id).addEventListener("change", render);
  $("side-by-side").addEventListener("change", () => {
    $("compare-views").hidden = !$("side-by-side").checked;
    render();
  });
  $("subject").addEventListener("change", placeHits);
  $("save").addEventListener("click", save);
  $("generate").addEventListener("click", generate);
  await render();
  document.body.dataset.ready = "1";
}

// Each region's hit box where the chosen subject holds its object (it moves with the
// subject's stature; the catalogue's rectangle for subjects of height 1).
function placeHits() {
  const subject = Number($("subject").value) - 1;
  for (const reg of cat.regions) {
    const [w, h] = reg.size;
    const [x, y, rw, rh] = reg.places[subject] ?? reg.rect;
    Object.assign($("hit" + reg.id).style, { left: x / w * 100 + "%", top: y / h * 100 + "%",
      width: rw / w * 100 + "%", height: rh / h * 100 + "%" });
  }
}

async function save() {
  $("save-status").textContent = "";
  try {
    const out = await post("/api/save", { ...settings(), name: $("save-name").value });
    $("save-status").textContent = "Saved " + out.folder + " and appended it to " + out.scenarios_csv;
    $("error").textContent = "";
  } catch (e) { $("error").textContent = e.message; }
}

async function generate() {
  $("gen-files").textContent = "";
  try {
    await post("/api/generate", { ...settings(), name: $("gen-name").value, count: Number($("gen-count").value) });
    $("error").textContent = "";
    poll();
  } catch (e) { $("error").textContent = e.message; }
}

async function poll() {
  const s = await (await fetch("/api/generate")).json();
  $("gen-progress").max = s.count || 1;
  $("gen-progress").value = s.done || 0;
  $("gen-status").textContent = s.name + ": " + s.state + ", " + (s.done || 0) + " of " + s.count;
  if (s.state === "running") { setTimeout(poll, 300); return; }
  if (s.state === "failed") $("error").textContent = s.error;
  for (const f of s.files || []) {
    const li = document.createElement("li");
    const a = document.createElement("a");
    a.href = "/files/" + encodeURIComponent(s.name) + "/" + encodeURIComponent(f); a.textContent = f;
    li.appendChild(a); $("gen-files").appendChild(li);
  }
}

init();
