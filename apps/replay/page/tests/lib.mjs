// Shared by the replay page's browser tests: Debian's Chromium, headless, software WebGL
// (SwiftShader), driven by puppeteer-core, with every request that is not file:, data: or blob:
// aborted and recorded (the page must load nothing). Each test fails on any console error, page
// error or network request.
import { existsSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

let puppeteer;
try {
  puppeteer = (await import('puppeteer-core')).default;
} catch (e) {
  console.error(
    'replay tests: puppeteer-core is not installed in apps/replay/page/node_modules; run\n' +
      `scripts/install-deps (or: cd apps/replay/page && npm ci). (${e.message})`);
  process.exit(1);
}

export const chromiumPath = process.env.KELP_CHROMIUM || '/usr/bin/chromium';

/// Fails the test with a message (exit status 1).
export function fail(msg) {
  console.error(`FAIL: ${msg}`);
  process.exit(1);
}
export function check(cond, msg) {
  if (!cond) fail(msg);
  console.log(`ok: ${msg}`);
}

/// The replay.html given on the command line (argv[2]).
export function replayFile() {
  const f = process.argv[2];
  if (!f) fail('usage: node <test>.mjs path/to/replay.html');
  if (!existsSync(f)) fail(`${f} does not exist (the fixture run did not write it?)`);
  return resolve(f);
}

export async function launch() {
  if (!existsSync(chromiumPath))
    fail(`${chromiumPath} not found: install Debian's chromium (scripts/install-deps) or set KELP_CHROMIUM`);
  const args = [
    '--use-angle=swiftshader', // software WebGL, as on a machine without a GPU
    '--enable-unsafe-swiftshader',
    '--ignore-gpu-blocklist',
    '--disable-dev-shm-usage',
    '--no-first-run',
    '--disable-background-networking',
    '--disable-component-update',
    '--disable-sync',
  ];
  // Chromium's sandbox refuses to run as root (CI containers)
  if (process.getuid && process.getuid() === 0) args.push('--no-sandbox');
  return puppeteer.launch({
    executablePath: chromiumPath,
    headless: true,
    args,
    defaultViewport: { width: 960, height: 600 },
    protocolTimeout: 600000,
  });
}

/// Opens replay.html?query in a new page of `browser` and waits for window.kelpReplay.ready.
/// Returns {page, problems}: problems collects console errors, page errors and network requests.
export async function open(browser, file, query = '') {
  const page = await browser.newPage();
  await page.bringToFront(); // a background tab gets no animation frames
  const problems = [];
  await page.setRequestInterception(true);
  page.on('request', (req) => {
    const url = req.url();
    if (/^(file|data|blob):/.test(url)) return req.continue();
    problems.push(`network request: ${url}`);
    return req.abort('blockedbyclient');
  });
  page.on('console', (m) => {
    if (m.type() === 'error') problems.push(`console error: ${m.text()}`);
  });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  const url = pathToFileURL(file).href + (query ? `?${query}` : '');
  page.setDefaultTimeout(300000);
  await page.goto(url, { waitUntil: 'load', timeout: 300000 });
  try {
    await page.waitForFunction(() => window.kelpReplay && window.kelpReplay.ready === true, { timeout: 120000 });
  } catch (e) {
    const msg = await page.evaluate(() => document.getElementById('message')?.textContent || '');
    fail(`the page did not become ready: ${msg} ${problems.join('; ')}`);
  }
  return { page, problems, url };
}

/// Fails if the page reported a console error, a page error or a network request.
export function checkClean(problems, what) {
  if (problems.length) fail(`${what}: ${problems.join('; ')}`);
  console.log(`ok: ${what}: no console error, no page error, no network request`);
}

/// Pixel coordinates of a NED point from the camera the page reports (column-major 4x4s).
export function projectNED(cam, ned) {
  const p = [ned[0], -ned[2], ned[1], 1]; // scene = (n, -d, e)
  const mul = (m, v) => [0, 1, 2, 3].map((r) => m[r] * v[0] + m[4 + r] * v[1] + m[8 + r] * v[2] + m[12 + r] * v[3]);
  const c = mul(cam.projectionMatrix, mul(cam.matrixWorldInverse, p));
  const ndc = [c[0] / c[3], c[1] / c[3]];
  return [((ndc[0] + 1) / 2) * cam.width, ((1 - ndc[1]) / 2) * cam.height];
}

/// The logged value of series array `a` (times `ts`) at t, linear between samples.
export function interp(ts, a, t) {
  let i = 0;
  while (i + 1 < ts.length && ts[i + 1] <= t) i++;
  if (i + 1 >= ts.length || ts[i] === t) return a[i];
  const u = (t - ts[i]) / (ts[i + 1] - ts[i]);
  return a[i] + (a[i + 1] - a[i]) * u;
}

// Screenshots are decoded by the page itself (an <img> from a data: URL drawn on a canvas), so
// the tests need no PNG library.
async function decodeScript(page, pngs, body, arg) {
  const urls = pngs.map((b) => `data:image/png;base64,${Buffer.from(b).toString('base64')}`);
  return page.evaluate(
    async (urls, body, arg) => {
      const images = await Promise.all(
        urls.map(async (u) => {
          const img = new Image();
          img.src = u;
          await img.decode();
          const c = document.createElement('canvas');
          c.width = img.width;
          c.height = img.height;
          const ctx = c.getContext('2d');
          ctx.drawImage(img, 0, 0);
          return { w: img.width, h: img.height, px: ctx.getImageData(0, 0, img.width, img.height).data };
        }));
      return new Function('images', 'arg', body)(images, arg);
    },
    urls, body, arg);
}

/// Compares two screenshots: the fraction of pixels that differ (any channel by more than 8),
/// and for each point [x, y] the distance [px] to the nearest differing pixel (null: none within
/// 40 px) and the bounding box [x0, y0, x1, y1] of the differing pixels within 40 px of it.
export function screenshotDiff(page, a, b, points = []) {
  return decodeScript(page, [a, b], `
    const [A, B] = images;
    if (A.w !== B.w || A.h !== B.h) return { fraction: 1, nearest: arg.map(() => null) };
    const diff = new Uint8Array(A.w * A.h);
    let count = 0;
    for (let i = 0; i < A.w * A.h; ++i) {
      const k = 4 * i;
      if (Math.abs(A.px[k] - B.px[k]) > 8 || Math.abs(A.px[k + 1] - B.px[k + 1]) > 8 ||
          Math.abs(A.px[k + 2] - B.px[k + 2]) > 8) { diff[i] = 1; count++; }
    }
    const boxes = [];
    const nearest = arg.map(([x, y]) => {
      let best = Infinity;
      const box = [Infinity, Infinity, -Infinity, -Infinity];
      const r = 40;
      for (let j = Math.max(0, Math.round(y) - r); j <= Math.min(A.h - 1, Math.round(y) + r); ++j)
        for (let i = Math.max(0, Math.round(x) - r); i <= Math.min(A.w - 1, Math.round(x) + r); ++i)
          if (diff[j * A.w + i]) {
            best = Math.min(best, Math.hypot(i + 0.5 - x, j + 0.5 - y));
            box[0] = Math.min(box[0], i); box[1] = Math.min(box[1], j);
            box[2] = Math.max(box[2], i + 1); box[3] = Math.max(box[3], j + 1);
          }
      boxes.push(best === Infinity ? null : box);
      return best === Infinity ? null : best;
    });
    return { fraction: count / (A.w * A.h), nearest, boxes };`, points);
}

/// The pixel of a screenshot within `radius` px of [x, y] whose colour is closest to `hex`
/// ('#rrggbb'): {distance (max channel difference), at: [x, y], colour}.
export function closestColourNear(page, png, point, radius, hex) {
  return decodeScript(page, [png], `
    const [A] = images;
    const want = [1, 3, 5].map((k) => parseInt(arg.hex.slice(k, k + 2), 16));
    let best = { distance: 256 };
    const [x, y] = arg.point;
    for (let j = Math.max(0, Math.floor(y - arg.radius)); j <= Math.min(A.h - 1, Math.ceil(y + arg.radius)); ++j)
      for (let i = Math.max(0, Math.floor(x - arg.radius)); i <= Math.min(A.w - 1, Math.ceil(x + arg.radius)); ++i) {
        const k = 4 * (j * A.w + i);
        const d = Math.max(...[0, 1, 2].map((c) => Math.abs(A.px[k + c] - want[c])));
        if (d < best.distance) best = { distance: d, at: [i, j], colour: [A.px[k], A.px[k + 1], A.px[k + 2]] };
      }
    return best;`, { point, radius, hex });
}
