// Drives the web viewer in the system's chromium (WebGPU on SwiftShader) for
// validation/tests/web.rs, which checks what it leaves in OUT:
//   node drive.mjs SITE_URL OUT
// - loads the quick scene at 160 x 100, 4 samples, in a 1000 x 800 window;
//   waits for it to converge; hides the overlay (i); screenshots the window
//   (window.png; where its parts are: layout.txt) and the canvas (page.png);
// - the Screenshot button's download (quick_shot.png);
// - ']' and the spin + button (spin up twice), a horizontal then a vertical
//   left drag, a wheel turn, a one-finger drag and a two-finger pinch, then
//   's': the saved view (quick_view.toml), which the test checks against the
//   same moves made by ViewState;
// - a scene with an unknown key pasted into the page: the message it shows;
//   then a good one (quick at 120 x 80): the image size and canvas it gets;
// - a browser without WebGPU (no navigator.gpu; and without the flag that
//   gives it an adapter): the page's messages;
// and writes each finding as NAME.txt (time to first frame, messages).
import puppeteer from 'puppeteer-core';
import fs from 'node:fs';
import path from 'node:path';

const [url, out] = process.argv.slice(2);
const chromium = process.env.CHROMIUM || '/usr/bin/chromium';
const TIMEOUT = 240_000;
// The window of the report: a 512 x 512 scene showed in its corner.
const [WIDTH, HEIGHT] = [1000, 800];
// WebGPU on SwiftShader (no GPU needed): the flags the guide and the page
// give; the test checks that the page's hint names each.
const WEBGPU = ['--enable-unsafe-webgpu', '--enable-features=Vulkan', '--use-vulkan=swiftshader',
  '--use-webgpu-adapter=swiftshader', '--use-angle=vulkan'];

function launch(webgpu) {
  const args = ['--no-sandbox', `--window-size=${WIDTH},${HEIGHT}`, '--force-device-scale-factor=1',
    ...WEBGPU.filter(f => webgpu || f !== '--enable-unsafe-webgpu')];
  const dir = fs.mkdtempSync(path.join(out, 'profile-'));
  return puppeteer.launch({
    executablePath: chromium, headless: true, args, userDataDir: dir,
    defaultViewport: { width: WIDTH, height: HEIGHT, deviceScaleFactor: 1, hasTouch: true },
    protocolTimeout: TIMEOUT,
  });
}

const state = page => page.evaluate(() => ({ ...document.body.dataset }));
const converged = page => page.waitForFunction(
  () => ['converged', 'error'].includes(document.body.dataset.state), { timeout: TIMEOUT });
// The page's counts of frames drawn and frames whose GPU work is done.
const counts = async page => {
  const s = await state(page);
  return { painted: Number(s.painted || 0), done: Number(s.done || 0) };
};
// After `act`: a frame drawn (and with `work`, new GPU work done and the image converged).
async function after(page, act, work) {
  const before = await counts(page);
  await act();
  await page.waitForFunction((b, work) => {
    const d = document.body.dataset;
    return work ? Number(d.done || 0) > b.done && d.state === 'converged'
      : Number(d.painted || 0) > b.painted;
  }, { timeout: TIMEOUT }, before, work);
}

async function waitFile(name) {
  const file = path.join(out, name);
  for (let i = 0; i < 600; i++) {
    if (fs.existsSync(file) && fs.statSync(file).size > 0) return file;
    await new Promise(r => setTimeout(r, 100));
  }
  throw new Error(`no download ${name}`);
}

// Two animation frames: the last input has been drawn.
const settle = page => page.evaluate(() => new Promise(r =>
  requestAnimationFrame(() => requestAnimationFrame(() => setTimeout(r, 200)))));

const summary = {};
const browser = await launch(true);
try {
  const page = await browser.newPage();
  const console_lines = [];
  page.on('console', m => console_lines.push(m.text()));
  const cdp = await page.createCDPSession();
  await cdp.send('Browser.setDownloadBehavior', { behavior: 'allow', downloadPath: path.resolve(out) });
  const sets = ['image.width=160', 'image.height=100', 'image.samples=4']
    .map(s => 'set=' + encodeURIComponent(s)).join('&');
  const t0 = Date.now();
  await page.goto(`${url}?scene=quick&${sets}`);
  await converged(page);
  summary.converged_ms = Date.now() - t0;
  let s = await state(page);
  if (s.state !== 'converged') throw new Error(`the page failed: ${s.message}`);
  summary.first_frame_ms = Number(s.firstFrameMs);
  const canvas = await page.$('#view');
  await canvas.focus();
  await after(page, () => page.keyboard.press('i'), false);
  await settle(page);
  const box = await canvas.boundingBox();
  // The page as a visitor sees it, and where its parts are.
  await page.screenshot({ path: path.join(out, 'window.png') });
  // One line each: `name values...`.
  const layout = await page.evaluate(() => {
    const rect = sel => {
      const r = document.querySelector(sel).getBoundingClientRect();
      return [r.x, r.y, r.width, r.height];
    };
    return {
      viewport: [innerWidth, innerHeight], canvas: rect('#view'), heading: rect('h1'),
      about: rect('#about'), title: document.title,
      text: [...document.querySelectorAll('h1, #about')].map(e => e.textContent.replace(/\s+/g, ' ')).join(' | '),
      image: document.body.dataset.image,
    };
  });
  summary.layout = Object.entries(layout)
    .map(([k, v]) => `${k} ${Array.isArray(v) ? v.join(' ') : v}`).join('\n');
  await page.screenshot({ path: path.join(out, 'page.png'), clip: box });

  await page.click('#shot');
  await waitFile('quick_shot.png');
  await canvas.focus();

  // Spin up, then move the camera: the drags and the wheel as the page got them.
  await after(page, () => page.keyboard.press(']'), true);
  // And once more with the page's button (screens without a keyboard).
  await after(page, () => page.click('#keys button[data-key="]"]'), true);
  const cx = box.x + box.width / 2, cy = box.y + box.height / 2;
  const touch = (type, points) => cdp.send('Input.dispatchTouchEvent', {
    type, touchPoints: points.map(([x, y], id) => ({ x, y, id })),
  });
  await after(page, async () => {
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    await page.mouse.move(cx + 40, cy, { steps: 4 });
    await page.mouse.up();
    await page.mouse.move(cx, cy);
    await page.mouse.down();
    await page.mouse.move(cx, cy + 12, { steps: 3 });
    await page.mouse.up();
    await page.mouse.wheel({ deltaY: -120 });
    // Touch: one finger 20 px to the right, then two spreading from 20 to 40 px apart.
    await touch('touchStart', [[cx, cy]]);
    for (let k = 1; k <= 4; k++) await touch('touchMove', [[cx + 5 * k, cy]]);
    await touch('touchEnd', []);
    await touch('touchStart', [[cx - 10, cy], [cx + 10, cy]]);
    for (let k = 1; k <= 5; k++) await touch('touchMove', [[cx - 10 - 2 * k, cy], [cx + 10 + 2 * k, cy]]);
    await touch('touchEnd', []);
  }, true);
  await page.keyboard.press('s');
  await waitFile('quick_view.toml');

  // A scene with a mistake, pasted into the page.
  const bad = '[image]\nwidth = 160\nheight = 100\nwidht = 3\npng = "x.png"\n' +
    '[camera]\nposition = [0.0, -30.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nfov = 40.0\n';
  await page.evaluate(text => {
    document.querySelector('details').open = true;
    document.getElementById('toml').value = text;
  }, bad);
  fs.writeFileSync(path.join(out, 'bad.toml'), bad);
  await page.click('#load');
  await page.waitForFunction(() => document.body.dataset.state === 'error', { timeout: TIMEOUT });
  summary.bad_message = await page.$eval('#message', e => e.textContent);

  // A good scene pasted: the running viewer changes to it (its size too).
  const good = (await (await fetch(new URL('configs/quick.toml', url))).text())
    .replace('width = 512', 'width = 120').replace('height = 512', 'height = 80')
    .replace('[image]', '[image]\nsamples = 2');
  await page.evaluate(text => { document.getElementById('toml').value = text; }, good);
  await page.click('#load');
  await page.waitForFunction(() => document.body.dataset.state === 'converged' &&
    document.body.dataset.target === '2', { timeout: TIMEOUT });
  const pasted = await (await page.$('#view')).boundingBox();
  summary.pasted_canvas = `${pasted.width}x${pasted.height}`;
  summary.pasted_image = await page.evaluate(() => document.body.dataset.image);
  summary.pasted_message = await page.$eval('#message', e => e.textContent);
  summary.console = console_lines;
} finally {
  await browser.close();
}

// Without WebGPU: a message in the page, not a blank canvas. The browser
// runs without the flag that gives WebGPU a software adapter, and the page
// is shown with no navigator.gpu at all.
const plain = await launch(false);
try {
  const page = await plain.newPage();
  await page.evaluateOnNewDocument(() => { delete Navigator.prototype.gpu; });
  await page.goto(url);
  await page.waitForFunction(() => document.body.dataset.state !== 'starting', { timeout: TIMEOUT });
  const s = await state(page);
  summary.no_webgpu = { state: s.state, message: s.message };
  // With navigator.gpu but (here) no adapter: said too, where so.
  const other = await plain.newPage();
  await other.goto(url);
  await other.waitForFunction(() => document.body.dataset.state !== 'starting', { timeout: TIMEOUT });
  const o = await state(other);
  summary.no_adapter = { state: o.state, message: o.message };
} finally {
  await plain.close();
}
// One file each, for the test to read without a JSON parser.
for (const [k, v] of Object.entries(summary)) {
  const text = typeof v === 'object' ? JSON.stringify(v) : String(v);
  fs.writeFileSync(path.join(out, `${k}.txt`), text);
}
fs.writeFileSync(path.join(out, 'no_webgpu_state.txt'), summary.no_webgpu.state || '');
fs.writeFileSync(path.join(out, 'no_webgpu_message.txt'), summary.no_webgpu.message || '');
fs.writeFileSync(path.join(out, 'webgpu_flags.txt'), WEBGPU.join(' '));
console.log(JSON.stringify(summary));
