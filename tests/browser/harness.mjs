// What the page's browser tests share: their checks, and `portalsim serve` opened in
// headless Chromium. Missing Chromium or puppeteer-core fails.
import { spawn } from "node:child_process";
import fs from "node:fs";
import puppeteer from "puppeteer-core";

export const CHROMIUM = "/usr/bin/chromium";

export function check(ok, what) {
  if (!ok) throw new Error("FAILED: " + what);
  console.log("ok: " + what);
}

// Starts `binary serve` on a free port over `root`, opens its page at `viewport` once the
// page says it is ready, runs `body({ page, url })`, then closes the browser and the server.
export async function withPage(binary, root, viewport, body) {
  check(fs.existsSync(CHROMIUM), CHROMIUM + " is installed");
  const server = spawn(binary, ["serve", "--port", "0", "--root", root], { stdio: ["ignore", "pipe", "inherit"] });
  let browser;
  try {
    const url = await new Promise((resolve, reject) => {
      let out = "";
      server.stdout.on("data", (d) => {
        out += d;
        const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
        if (m) resolve(m[0]);
      });
      server.on("exit", (code) => reject(new Error("server exited with " + code)));
      setTimeout(() => reject(new Error("no URL from the server in 60 s")), 60000).unref();
    });
    browser = await puppeteer.launch({
      executablePath: CHROMIUM, headless: true,
      args: ["--no-sandbox", "--no-proxy-server", "--disable-gpu"],
    });
    const page = await browser.newPage();
    await page.setViewport(viewport);
    await page.goto(url);
    await page.waitForSelector("body[data-ready='1']", { timeout: 60000 });
    await body({ page, url });
  } finally {
    if (browser) await browser.close();
    server.kill("SIGTERM");
  }
}
