// The replay page loads from file:// in headless Chromium (software WebGL) with no console error
// and no network request, in each camera; the view at t = 0 and at t = 40 s differ.
// usage: node load.mjs path/to/replay.html
import { launch, open, checkClean, check, replayFile, screenshotDiff } from './lib.mjs';

const file = replayFile();
const browser = await launch();
try {
  const shots = {};
  for (const [name, query] of [
    ['t0', 't=0&paused=1&camera=follow'],
    ['t40', 't=40&paused=1&camera=follow'],
    ['underwater', 't=40&paused=1&camera=underwater'],
    ['orbit', 't=40&paused=1&camera=orbit'],
    ['playing', 'camera=follow&speed=4'],
  ]) {
    const { page, problems } = await open(browser, file, query);
    const state = await page.evaluate(() => ({
      time: window.kelpReplay.time, playing: window.kelpReplay.playing, camera: window.kelpReplay.cameraMode,
      duration: window.kelpReplay.duration, frames: window.kelpReplay.frames,
    }));
    if (name === 'playing') {
      // it plays: time advances, frames are drawn
      await page.waitForFunction((f) => window.kelpReplay.frames > f + 5, { timeout: 120000 }, state.frames);
      const later = await page.evaluate(() => window.kelpReplay.time);
      check(state.playing && later > state.time, `without ?paused the replay plays (t ${state.time.toFixed(2)} -> ${later.toFixed(2)} s)`);
    } else {
      const t = name === 't0' ? 0 : 40;
      check(!state.playing && Math.abs(state.time - Math.min(t, state.duration)) < 1e-9 && state.camera === query.split('camera=')[1],
        `${query}: opens paused at t = ${state.time} s with the ${state.camera} camera`);
      shots[name] = await page.screenshot({ type: 'png' });
      if (name === 't40') shots.page = page;
    }
    checkClean(problems, query);
    if (name !== 't40') await page.close();
  }
  const d = await screenshotDiff(shots.page, shots.t0, shots.t40);
  check(d.fraction > 0.02, `the screenshots at t = 0 and t = 40 s differ (${(100 * d.fraction).toFixed(1)} % of pixels)`);
  const u = await screenshotDiff(shots.page, shots.t40, shots.underwater);
  check(u.fraction > 0.02, `the underwater view differs from the follow view (${(100 * u.fraction).toFixed(1)} % of pixels)`);
} finally {
  await browser.close();
}
