// The models on the page of `portalsim serve`, in headless Chromium (run by ctest):
//   node serve_models.test.mjs PORTALSIM_BINARY WORK_DIR [SCREENSHOT.png]
// Every knob of the registry (/api/knobs) has its control; the model selector and a
// physics knob reach the server (the saved folder equals simulate's with the same flags,
// byte for byte); a knob out of range shows its flag's message; the side-by-side view
// shows one scenario under both models with simulate's zones. Missing Chromium fails.
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { check, withPage } from "./harness.mjs";

const [binary, work, shot] = process.argv.slice(2);
if (!binary || !work) throw new Error("usage: serve_models.test.mjs PORTALSIM_BINARY WORK_DIR [SCREENSHOT.png]");
const GUN = ["none", "none", "none", "gun"];


// simulate's folder for the gun in region 4 with these flags; returns its path.
function simulate(name, flags) {
  const dir = path.join(work, name);
  const r = spawnSync(binary, ["simulate", ...GUN, "--out", dir, ...flags], { encoding: "utf8" });
  check(r.status === 0, "simulate " + flags.join(" ") + " ran: " + r.stderr);
  return dir;
}
const zonesOf = (dir) => fs.readFileSync(path.join(dir, "metal.txt"), "utf8").trim().split(/[,\s]+/).map(Number).join(",");

fs.rmSync(work, { recursive: true, force: true });
const root = path.join(work, "root");
fs.mkdirSync(root, { recursive: true });
const thesisDir = simulate("sim-thesis", []);
const physicsDir = simulate("sim-physics", ["--model", "physics"]);
const netdDir = simulate("sim-netd", ["--model", "physics", "--netd", "0.5"]);
const THESIS = zonesOf(thesisDir), PHYSICS = zonesOf(physicsDir);
check(THESIS !== PHYSICS, "the two models' zones differ: " + THESIS + " | " + PHYSICS);

await withPage(binary, root, { width: 1400, height: 1300 }, async ({ page, url }) => {
  const rendered = () => page.$eval("body", (b) => Number(b.dataset.rendered));
  // Waits for a render after `act` and returns the zones shown.
  async function after(act) {
    const before = await rendered();
    await act();
    await page.waitForFunction((n) => Number(document.body.dataset.rendered) > n, { timeout: 60000 }, before);
    return page.$eval("#zones", (o) => o.value);
  }

  // Every knob of the registry has its control, with the registry's default.
  const knobs = await (await fetch(url + "api/knobs")).json();
  check(knobs.length >= 15, knobs.length + " knobs listed");
  for (const k of knobs) {
    const c = await page.$("#knob-" + k.key);
    check(c !== null, "control for " + k.flag);
    const v = await c.evaluate((e) => (e.type === "checkbox" ? (e.checked ? "on" : "off") : e.value));
    check(v === (k.fidelity ? "" : k.default), k.flag + " shows " + JSON.stringify(v));
  }
  check((await page.$$eval("[id^='knob-']", (l) => l.length)) === knobs.length, "no control without its knob");
  const modelChoices = await page.$$eval("#knob-model option", (o) => o.map((e) => e.value).join(","));
  check(modelChoices === "thesis,physics", "model selector offers " + modelChoices);

  // The gun in region 4, then the physics model: the page shows simulate's physics zones.
  await after(() => page.select("#region4", "gun:h"));
  check((await page.$eval("#zones", (o) => o.value)) === THESIS, "thesis zones " + THESIS);
  const thesisUpper = await page.$eval("#upper", (i) => i.src);
  const z = await after(() => page.select("#knob-model", "physics"));
  check(z === PHYSICS, "physics zones " + z);
  check((await page.$eval("#upper", (i) => i.src)) !== thesisUpper, "upper MMW image changed with the model");

  // A physics knob reaches the server: saved with --netd 0.5, equal to simulate's bytes.
  await after(() => page.$eval("#knob-netd", (e) => { e.value = "0.5"; e.dispatchEvent(new Event("change")); }));
  await page.$eval("#save-name", (e) => { e.value = "netd"; });
  await page.click("#save");
  await page.waitForFunction(() => document.getElementById("save-status").textContent.startsWith("Saved"),
    { timeout: 60000 });
  const saved = path.join(root, "netd");
  const names = fs.readdirSync(netdDir).sort();
  check(JSON.stringify(names) === JSON.stringify(fs.readdirSync(saved).sort()), "same files: " + names.join(" "));
  for (const n of names)
    check(Buffer.compare(fs.readFileSync(path.join(netdDir, n)), fs.readFileSync(path.join(saved, n))) === 0,
      n + " equals simulate --model physics --netd 0.5 byte for byte");

  // Out of range: the knob's flag and its range on the page.
  await page.$eval("#knob-netd", (e) => { e.value = "1000"; e.dispatchEvent(new Event("change")); });
  await page.waitForFunction(() => document.getElementById("error").textContent.includes("--netd"),
    { timeout: 60000 });
  const err = await page.$eval("#error", (e) => e.textContent);
  check(err.includes("0 .. 100"), "out-of-range message: " + err);
  await after(() => page.$eval("#knob-netd", (e) => { e.value = "3"; e.dispatchEvent(new Event("change")); }));
  check((await page.$eval("#error", (e) => e.textContent)) === "", "the message goes when the value is good");

  // A knob that may be drawn per scenario takes A..B (Generate's data set draws it); a
  // reversed range is refused with the flag's message.
  check((await page.$eval("#knob-netd", (e) => e.type)) === "text", "--netd is a text field: a number or A..B");
  await after(() => page.$eval("#knob-netd", (e) => { e.value = "1..4"; e.dispatchEvent(new Event("change")); }));
  check((await page.$eval("#error", (e) => e.textContent)) === "", "a range renders");
  await page.$eval("#knob-netd", (e) => { e.value = "4..1"; e.dispatchEvent(new Event("change")); });
  await page.waitForFunction(() => document.getElementById("error").textContent.includes("reversed"),
    { timeout: 60000 });
  await after(() => page.$eval("#knob-netd", (e) => { e.value = "3"; e.dispatchEvent(new Event("change")); }));

  // Side by side: one scenario, both models, each with simulate's zones.
  check(await page.$eval("#compare-views", (e) => e.hidden), "side by side starts hidden");
  await after(() => page.click("#side-by-side"));
  check(!(await page.$eval("#compare-views", (e) => e.hidden)), "side by side shown");
  const tz = await page.$eval("#thesis-zones", (o) => o.value), pz = await page.$eval("#physics-zones", (o) => o.value);
  check(tz === THESIS, "left column: thesis zones " + tz);
  check(pz === PHYSICS, "right column: physics zones " + pz);
  const srcs = await page.$$eval("#compare-views img", (l) => l.map((i) => i.src));
  check(srcs.length === 6 && srcs.every((s) => s.startsWith("data:image/png;base64,")), "six images shown");
  check(srcs[0] !== srcs[3] && srcs[1] !== srcs[4], "the models' MMW views differ");
  const thesisPng = "data:image/png;base64," + fs.readFileSync(path.join(thesisDir, "upper.png")).toString("base64");
  check(srcs[0] === thesisPng, "thesis column's upper view is simulate's upper.png");

  await page.screenshot({ path: shot || path.join(work, "serve_models.png"), fullPage: true });
  console.log("screenshot " + (shot || path.join(work, "serve_models.png")));
});
