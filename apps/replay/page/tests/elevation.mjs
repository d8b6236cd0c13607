// The page's sea surface is kelp's: its elevation(x, y, t) equals the data's elevation_check
// values (computed by kelp) within 1e-6 m, and the sea mesh drawn at t = 40 s follows it.
// usage: node elevation.mjs path/to/replay.html
import { launch, open, checkClean, check, fail, replayFile } from './lib.mjs';

const file = replayFile();
const browser = await launch();
try {
  const { page, problems } = await open(browser, file, 't=40&paused=1&camera=follow');
  const r = await page.evaluate(() => {
    const d = window.kelpReplay.data;
    return {
      n: d.waves.components.amplitude.length,
      checks: d.elevation_check.map(([x, y, t, z]) => [x, y, t, z, window.kelpReplay.elevation(x, y, t)]),
    };
  });
  if (r.checks.length < 10) fail(`elevation_check has only ${r.checks.length} samples`);
  let worst = 0, amplitude = 0;
  for (const [x, y, t, z, page] of r.checks) {
    worst = Math.max(worst, Math.abs(page - z));
    amplitude = Math.max(amplitude, Math.abs(z));
  }
  check(amplitude > 0.01, `the samples see waves (|zeta| up to ${amplitude.toFixed(3)} m, ${r.n} components)`);
  check(worst <= 1e-6, `the page's elevation equals kelp's at ${r.checks.length} points: worst difference ${worst.toExponential(2)} m <= 1e-6 m`);
  // the mesh: inner vertices at the elevation of their (float32) position
  const mesh = await page.evaluate(() => {
    const k = window.kelpReplay;
    const out = [];
    for (let i = 1; i < k.seaGrid; i += 7)
      for (let j = 1; j < k.seaGrid; j += 7) {
        const [n, e, z] = k.seaVertex(i, j);
        out.push(Math.abs(z - k.elevation(n, e, k.time)));
      }
    return out;
  });
  const meshWorst = Math.max(...mesh);
  check(meshWorst <= 1e-4, `the sea mesh at t = 40 s is at that elevation (${mesh.length} vertices, worst ${meshWorst.toExponential(2)} m; float32 positions)`);
  checkClean(problems, 'elevation');
} finally {
  await browser.close();
}
