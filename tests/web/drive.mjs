// Drives the browser build in headless Chromium with WebGPU, for the web
// tests (tests/web/main.rs): serves target/web (and the test's files) on
// the loopback, plays one scenario with real mouse and keys, and leaves
// what it saw in OUT: console.json (every console message), PNG
// screenshots and the page's downloads. The Rust side checks them.
//
//   node tests/web/drive.mjs SCENARIO OUT [FILE]
//
// (For `bench`, FILE is the rest of the page's query, e.g. shading=preview.)
import http from "node:http";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";
import puppeteer from "puppeteer-core";

const [scenario, out, given] = process.argv.slice(2);
const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../../target/web");
const chromium = process.env.OCTOVOX_CHROMIUM || "/usr/bin/chromium";
// The camera both the page and `octovox render` use (tests/web/main.rs).
export const CAMERA = "96,70,110:32,8,32";
const TIMEOUT_MS = Number(process.env.OCTOVOX_WEB_TIMEOUT_MS || 120000);

const types = { ".html": "text/html", ".js": "text/javascript", ".wasm": "application/wasm" };

/// target/web at /, and the test's own file at /given/NAME.
function serve() {
  const server = http.createServer((req, res) => {
    const url = new URL(req.url, "http://localhost");
    let file = url.pathname === "/" ? path.join(root, "index.html") : path.join(root, url.pathname);
    if (given && url.pathname === "/given/" + path.basename(given)) file = given;
    if (!file.startsWith(root) && file !== given) {
      res.writeHead(403).end();
      return;
    }
    fs.readFile(file, (err, bytes) => {
      if (err) {
        res.writeHead(404).end();
        return;
      }
      res.writeHead(200, { "content-type": types[path.extname(file)] || "application/octet-stream" }).end(bytes);
    });
  });
  return new Promise((resolve) => server.listen(0, "127.0.0.1", () => resolve(server)));
}

const server = await serve();
const base = `http://127.0.0.1:${server.address().port}`;
// WebGPU on SwiftShader: without the Vulkan flags the canvas screenshots
// blank. The `nogpu` scenario is a browser without WebGPU (Chromium on
// Linux without the flag).
const webgpu = ["--enable-unsafe-webgpu", "--enable-features=Vulkan", "--use-vulkan=swiftshader", "--use-angle=vulkan"];
const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ["--no-sandbox", "--window-size=1280,720", ...(scenario === "nogpu" ? [] : webgpu)],
});
const messages = [];
let page;

function lines() {
  return messages.map((m) => m.text);
}

/// Waits until a console line matches `re`; returns it.
async function line(re, after = 0) {
  const start = Date.now();
  while (Date.now() - start < TIMEOUT_MS) {
    const found = lines().slice(after).find((l) => re.test(l));
    if (found) return found;
    await new Promise((r) => setTimeout(r, 50));
  }
  throw new Error(`no console line ${re} in ${TIMEOUT_MS} ms; the page said:\n${lines().join("\n")}`);
}

/// Loads the page (again: a reload, the browser's storage kept) and waits
/// until it is ready.
async function open(query) {
  if (!page) {
    page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 720 });
    page.on("console", (m) => messages.push({ type: m.type(), text: m.text() }));
    page.on("pageerror", (e) => messages.push({ type: "pageerror", text: e.message }));
    page.on("dialog", (d) => d.accept(answers.shift() ?? d.defaultValue()));
    const cdp = await page.createCDPSession();
    await cdp.send("Browser.setDownloadBehavior", { behavior: "allow", downloadPath: out, eventsEnabled: true });
  }
  const from = messages.length;
  await page.goto(`${base}/${query}`);
  await line(/^octovox: ready/, from);
  // The pointer starts over the menu bar: keep it off the scene.
  await page.mouse.move(640, 10);
}

/// Answers of the browser's prompts (Save As, Export), in order.
const answers = [];

async function keys(...combo) {
  const held = combo.slice(0, -1);
  for (const k of held) await page.keyboard.down(k);
  await page.keyboard.press(combo.at(-1));
  for (const k of held.reverse()) await page.keyboard.up(k);
}

/// Save As NAME: the prompt answered, the download waited for.
async function saveAs(name) {
  const from = messages.length;
  answers.push(name);
  await keys("Control", "Shift", "KeyS");
  await line(new RegExp(`^downloaded: ${name.replace(".", "\\.")}$`), from);
  await waitForFile(path.join(out, name));
}

async function waitForFile(file) {
  const start = Date.now();
  while (!fs.existsSync(file) && Date.now() - start < TIMEOUT_MS) await new Promise((r) => setTimeout(r, 50));
}

/// Gives the page `file` through its file picker, opened by `combo`.
/// Puppeteer turns the picker's interception on asynchronously, and a
/// picker that opens before that is missed: the keys are pressed again
/// (the page asks for one file at a time) until one is caught, for as long
/// as any wait here (a page busy drawing on a loaded machine answers keys
/// late).
async function pick(file, ...combo) {
  const start = Date.now();
  for (;;) {
    // Its failure is taken at once: the keys below may take longer than
    // the wait, and a rejection nobody handles yet ends node.
    const chooser = page.waitForFileChooser({ timeout: 5000 }).catch((err) => err);
    await page.evaluate(() => 0);
    await keys(...combo);
    const got = await chooser;
    if (!(got instanceof Error)) {
      await got.accept([file]);
      return;
    }
    if (Date.now() - start >= TIMEOUT_MS) throw got;
  }
}

async function frames(n) {
  // A few animation frames, so that what was submitted is on the canvas.
  for (let i = 0; i < n; i++) await page.evaluate(() => new Promise((r) => requestAnimationFrame(r)));
}

async function shot(name) {
  await frames(3);
  await page.screenshot({ path: path.join(out, name) });
}

const scenarios = {
  // The demo scene from a fixed camera, for the native render to compare with.
  async start() {
    await open(`?shading=preview&camera=${CAMERA}`);
    await shot("start.png");
  },
  // Saves the scene, places a voxel with a click, erases one with a right
  // click, takes the erase back with Ctrl+Z, saves again.
  async edit() {
    await open(`?shading=preview&camera=${CAMERA}`);
    await saveAs("before.vox");
    await shot("before.png");
    let from = messages.length;
    await page.mouse.click(640, 420);
    await line(/^edit: /, from);
    await shot("placed.png");
    from = messages.length;
    await page.mouse.click(800, 600, { button: "right" });
    await line(/^edit: /, from);
    from = messages.length;
    await keys("Control", "KeyZ");
    await line(/^undo: /, from);
    await saveAs("after.vox");
  },
  // File ▸ Open (Ctrl+O) with the browser's picker, then Save As.
  async open() {
    await open("?shading=preview");
    await pick(given, "Control", "KeyO");
    await line(new RegExp(`^loaded: ${path.basename(given)}`));
    await saveAs("copy.vox");
  },
  // ?open=URL: a model shared as a link.
  async link() {
    await open(`?shading=preview&open=/given/${path.basename(given)}`);
    await line(new RegExp(`^loaded: ${path.basename(given)}`));
    await saveAs("linked.vox");
  },
  // Edits, then a reload: the page offers them back (the journal in the
  // browser's storage), and Recover brings them; the demo scene saved by
  // an earlier page beside it.
  async recover() {
    await open(`?shading=preview&camera=${CAMERA}`);
    await saveAs("before.vox");
    await open(`?shading=preview&camera=${CAMERA}`);
    let from = messages.length;
    await page.mouse.click(640, 420);
    await line(/^edit: /, from);
    from = messages.length;
    await open(`?shading=preview&camera=${CAMERA}`);
    await line(/^asking: recover /, from);
    // The dialog's first button (Recover) takes the keyboard focus with Tab.
    await keys("Tab");
    await keys("Enter");
    await line(/^recovered: the untitled scene$/);
    await keys("Escape");
    await saveAs("recovered.vox");
  },
  // Time to the first frame and `?bench-frames=N` (docs/bench/web.md):
  // QUERY is the rest of the page's query.
  async bench() {
    const started = Date.now();
    await open(`?bench-frames=${process.env.OCTOVOX_BENCH_FRAMES || 60}&${given || ""}`);
    const firstFrameMs = Date.now() - started;
    const bench = await line(/^bench: /);
    fs.writeFileSync(path.join(out, "bench.json"), JSON.stringify({ firstFrameMs, bench }));
    console.log(`first frame after ${firstFrameMs} ms; ${bench}`);
  },
  // A browser without WebGPU: the page says so instead of a blank canvas.
  async nogpu() {
    page = await browser.newPage();
    page.on("console", (m) => messages.push({ type: m.type(), text: m.text() }));
    await page.goto(`${base}/`);
    await page.waitForSelector("#status.error", { timeout: TIMEOUT_MS });
    const shown = await page.$eval("#status", (e) => (e.hidden ? "" : e.textContent.trim()));
    fs.writeFileSync(path.join(out, "status.txt"), shown);
    await shot("nogpu.png");
  },
  // An edit of an opened file, a reload: the page says the edits are
  // kept; opening the file again offers them back.
  async reopen() {
    await open("?shading=preview");
    await pick(given, "Control", "KeyO");
    await line(new RegExp(`^loaded: ${path.basename(given)}`));
    await page.mouse.move(640, 10);
    await saveAs("before.vox");
    let from = messages.length;
    await page.mouse.click(758, 372);
    await line(/^edit: /, from);
    from = messages.length;
    await open("?shading=preview");
    await line(new RegExp(`^kept: before\\.vox$`), from);
    from = messages.length;
    await pick(path.join(out, "before.vox"), "Control", "KeyO");
    await line(/^asking: recover /, from);
    await keys("Tab");
    await keys("Enter");
    await line(/^recovered: before\.vox$/, from);
    await keys("Escape");
    await saveAs("recovered.vox");
  },
  // A file opened, a reload: File ▸ Open recent (real clicks on the menu)
  // opens it again from the browser's storage.
  async recent() {
    await open("?shading=preview");
    await pick(given, "Control", "KeyO");
    await line(new RegExp(`^loaded: ${path.basename(given)}`));
    let from = messages.length;
    await open("?shading=preview");
    await page.mouse.click(19, 12); // File
    await page.mouse.move(60, 85, { steps: 5 }); // Open recent ▸
    await new Promise((r) => setTimeout(r, 500));
    await page.mouse.move(205, 85, { steps: 10 }); // the newest entry
    await shot("recent-menu.png");
    await page.mouse.click(205, 85);
    await line(new RegExp(`^loaded: ${path.basename(given)}`), from);
    await saveAs("reopened.vox");
  },
  // File ▸ Export mesh… (Ctrl+E) of a model shared as a link: the
  // prompt answered with a .glb name, the mesh downloaded.
  async export() {
    await open(`?shading=preview&open=/given/${path.basename(given)}`);
    await line(new RegExp(`^loaded: ${path.basename(given)}`));
    const from = messages.length;
    answers.push("model.glb");
    await keys("Control", "KeyE");
    await line(/^downloaded: model\.glb$/, from);
    await waitForFile(path.join(out, "model.glb"));
  },
  // File ▸ Play script… (Ctrl+Shift+P): the script's own `save` line
  // writes the file the page downloads.
  async replay() {
    await open("?shading=preview");
    await pick(given, "Control", "Shift", "KeyP");
    await line(/^replay: \d+ passed, \d+ failed$/);
    await frames(2);
  },
};

try {
  if (!scenarios[scenario]) throw new Error(`no scenario ${scenario}`);
  await scenarios[scenario]();
} finally {
  fs.writeFileSync(path.join(out, "console.json"), JSON.stringify(messages, null, 1));
  await browser.close();
  server.close();
}
