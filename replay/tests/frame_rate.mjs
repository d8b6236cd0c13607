// Measures (does not assert) the replay's frame rate while playing at 1x with the follow camera,
// and prints it with the page's size, for the run given (CTest: a 10-minute run with 40 nodes).
// Software rendering (SwiftShader), headless: the numbers depend on the machine and its load.
// usage: node frame_rate.mjs path/to/replay.html [seconds]
import { statSync } from 'node:fs';
import { launch, open, checkClean, check, replayFile } from './lib.mjs';

const file = replayFile();
const seconds = Number(process.argv[3] || 10);
const browser = await launch();
try {
  const { page, problems } = await open(browser, file, 't=30&camera=follow&paused=1');
  const info = await page.evaluate(() => {
    const d = window.kelpReplay.data;
    return { duration: d.duration, samples: d.series.t.length, nodeSamples: d.nodes.t.length,
      nodes: Math.max(...d.nodes.position.map((p) => p.length / 3)), components: d.waves.components.amplitude.length };
  });
  const r = {};
  for (const camera of ['follow', 'underwater']) {
    r[camera] = await page.evaluate(async (camera, s) => {
      window.kelpReplay.setCamera(camera);
      return window.kelpReplay.measureFps(s);
    }, camera, seconds);
  }
  const size = statSync(file).size;
  console.log(`replay frame rate (headless Chromium, SwiftShader software WebGL, 960x600, this machine under its current load):`);
  console.log(`  run: ${info.duration} s, ${info.samples} log samples, ${info.nodeSamples} node samples, up to ${info.nodes} nodes, ${info.components} wave components; replay.html ${(size / 1e6).toFixed(2)} MB`);
  for (const [camera, m] of Object.entries(r))
    console.log(`  ${camera} camera: ${m.fps.toFixed(1)} frames/s (${m.frames} frames in ${m.seconds.toFixed(1)} s; ${m.workMs.toFixed(1)} ms of JS update + render call per frame)`);
  check(r.follow.frames > 0 && r.underwater.frames > 0, 'the replay draws frames while playing');
  checkClean(problems, 'frame rate');
} finally {
  await browser.close();
}
