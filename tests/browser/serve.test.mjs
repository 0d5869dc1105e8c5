// End-to-end test of `portalsim serve` in headless Chromium (run by ctest):
//   node serve.test.mjs PORTALSIM_BINARY WORK_DIR [SCREENSHOT.png]
// Loads the page, puts a gun in region 4 by clicking the body, checks the images changed
// and the zones equal the thesis's example, saves, compares the folder with simulate's
// byte for byte, and takes a screenshot. Missing node, puppeteer-core or Chromium fails.
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { check, withPage } from "./harness.mjs";

const [binary, work, shot] = process.argv.slice(2);
if (!binary || !work) throw new Error("usage: serve.test.mjs PORTALSIM_BINARY WORK_DIR [SCREENSHOT.png]");
const THESIS = "193,112,75,2,1,1,96,200,200,190,196,53,53,94,64,82,53,200,200";


fs.rmSync(work, { recursive: true, force: true });
const root = path.join(work, "root");
fs.mkdirSync(root, { recursive: true });

await withPage(binary, root, { width: 1280, height: 1000 }, async ({ page, url }) => {
  const before = await page.$eval("#upper", (i) => i.src);
  const beforeIr = await page.$eval("#ir", (i) => i.src);
  const zonesBefore = await page.$eval("#zones", (o) => o.value);

  // Region 4 on the body, clicked with the mouse at its centre.
  const box = await (await page.$("#hit4")).boundingBox();
  await page.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
  await page.waitForFunction((want) => document.getElementById("zones").value === want, { timeout: 30000 }, THESIS);
  check(zonesBefore !== THESIS, "zones changed after the click");
  check(await page.$eval("#region4", (s) => s.value.startsWith("gun")), "region 4 holds the gun");
  check(await page.$eval("#zones", (o) => o.value) === THESIS, "zones shown equal the thesis's " + THESIS);
  const bars = await page.$$eval(".zone .value", (v) => v.map((e) => e.textContent).join(","));
  check(bars === THESIS, "the two panels' values read " + bars);
  check((await page.$eval("#upper", (i) => i.src)) !== before, "upper MMW image changed");
  check((await page.$eval("#ir", (i) => i.src)) !== beforeIr, "IR image changed");

  // A bad rule: HTTP 400, its message on the page.
  await page.type("#rule", "gun&");
  await page.keyboard.press("Tab");
  await page.waitForFunction(() => document.getElementById("error").textContent.includes("gun&"), { timeout: 30000 });
  const ruleError = await page.$eval("#error", (e) => e.textContent);
  check(ruleError.includes('"gun&" at character 5'), "a bad rule's message is shown, saying where: " + ruleError);
  await page.$eval("#rule", (e) => { e.value = ""; });
  await page.$eval("#rule", (e) => e.dispatchEvent(new Event("change")));
  await page.waitForFunction(() => document.getElementById("error").textContent === "", { timeout: 30000 });

  // Save, then compare with simulate's folder byte for byte.
  await page.$eval("#save-name", (e) => { e.value = "gun4"; });
  await page.click("#save");
  await page.waitForFunction(() => document.getElementById("save-status").textContent.startsWith("Saved"),
    { timeout: 30000 });
  const sim = path.join(work, "sim");
  const r = spawnSync(binary, ["simulate", "none", "none", "none", "gun", "--out", sim], { encoding: "utf8" });
  check(r.status === 0, "simulate ran: " + r.stdout.trim() + r.stderr);
  const saved = path.join(root, "gun4");
  const names = fs.readdirSync(sim).sort();
  check(JSON.stringify(names) === JSON.stringify(fs.readdirSync(saved).sort()), "same files: " + names.join(" "));
  for (const n of names)
    check(Buffer.compare(fs.readFileSync(path.join(sim, n)), fs.readFileSync(path.join(saved, n))) === 0,
      n + " equals simulate's byte for byte");
  check(fs.readFileSync(path.join(root, "scenarios.csv"), "utf8").includes("1,none,none,none,gun:h,"),
    "scenarios.csv has the saved row");

  // Keyboard: the regions are buttons with names, reachable by Tab.
  const label = await page.$eval("#hit4", (b) => b.getAttribute("aria-label"));
  check(/region 4 .*gun/.test(label), "region 4 is labelled: " + label);
  const png = shot || path.join(work, "serve.png");
  await page.screenshot({ path: png });
  const signature = Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
  check(fs.existsSync(png) && fs.statSync(png).size > 1000 && fs.readFileSync(png).subarray(0, 8).equals(signature),
    "screenshot " + png + " is a PNG");
});
