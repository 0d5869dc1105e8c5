// The page of `portalsim serve`: every change posts the settings to /api/render and
// redraws the three sensors; errors from the server are shown as they come.
"use strict";
const $ = (id) => document.getElementById(id);
let cat = null;
let pending = 0;

function settings() {
  const objects = [];
  for (let r = 1; r <= cat.regions.length; ++r) objects.push($("region" + r).value);
  return {
    subject: Number($("subject").value), seed: $("seed").value, tier: $("tier").value, placement: $("placement").value,
    palette: $("palette").value,
    pattern_noise: $("pattern-noise").checked, pixel_noise: Number($("pixel-noise").value),
    rule: $("rule").value.trim(), threat: $("threat").value, objects,
  };
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
    for (const v of ["upper", "lower", "ir"]) $(v).src = out[v];
    drawZones(out.metal);
    $("label").textContent = "Threat: " + (out.threat ? "yes" : "no");
    $("error").textContent = "";
    document.body.dataset.rendered = String(ticket);
  } catch (e) {
    if (ticket === pending) $("error").textContent = e.message;
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

async function init() {
  cat = await (await fetch("/api/catalogue")).json();
  cat.subjects.forEach((s, i) => option($("subject"), i + 1, (i + 1) + " " + s));
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
  for (let z = 1; z <= 19; ++z) {
    const row = document.createElement("div");
    row.className = "zone"; row.id = "zone" + z; row.setAttribute("role", "img");
    row.innerHTML = '<span class="name">' + z + '</span><div class="bar"><div></div></div><span class="value"></span>';
    $(z <= 9 ? "panel-a" : "panel-b").appendChild(row);
  }
  for (const id of ["subject", "seed", "tier", "placement", "palette", "pattern-noise", "pixel-noise", "rule", "threat"])
    $(id).addEventListener("change", render);
  $("subject").addEventListener("change", placeHits);
  $("save").addEventListener("click", save);
  $("generate").addEventListener("click", generate);
  await render();
  document.body.dataset.ready = "1";
}

// Each region's hit box where the chosen subject holds its object (it moves with the
// subject's stature; the catalogue's rectangle for subjects of height 1).
function placeHits() {
  const [w, h] = cat.mmw;
  const subject = Number($("subject").value) - 1;
  for (const reg of cat.regions) {
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
