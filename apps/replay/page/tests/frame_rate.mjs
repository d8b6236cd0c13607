// Measures (does not assert) the replay's frame rate while playing at 1x with the follow camera,
// and prints it with the page's size, for the run given (CTest: a 10-minute run with 40 nodes).
// Software rendering (SwiftShader), headless: the numbers depend on the machine and its load.
// usage: node frame_rate.mjs path/to/replay.html [seconds]
import { statSync, readFileSync, readdirSync } from 'node:fs';
import { launch, open, checkClean, check, replayFile } from './lib.mjs';

const file = replayFile();
const seconds = Number(process.argv[3] || 10);
const browser = await launch();
// CPU time [s] used so far by Chromium (all its processes: the browser, the renderer, the GPU
// process that runs SwiftShader), from Linux's /proc (null elsewhere). Per frame it says what a
// frame costs whatever the machine's load.
function chromiumCpu() {
  try {
    const children = {}, cpu = {};
    const tick = 100; // USER_HZ, 100 on Linux
    for (const d of readdirSync('/proc')) {
      if (!/^\d+$/.test(d)) continue;
      try {
        const s = readFileSync(`/proc/${d}/stat`, 'utf8');
        const f = s.slice(s.lastIndexOf(')') + 2).split(' ');
        (children[f[1]] ||= []).push(d);
        cpu[d] = (Number(f[11]) + Number(f[12])) / tick;
      } catch {
        // the process ended meanwhile
      }
    }
    let sum = 0;
    const stack = [String(browser.process().pid)];
    while (stack.length) {
      const p = stack.pop();
      sum += cpu[p] || 0;
      stack.push(...(children[p] || []));
    }
    return sum;
  } catch {
    return null;
  }
}
try {
  const { page, problems } = await open(browser, file, 't=30&camera=follow&paused=1');
  const info = await page.evaluate(() => {
    const d = window.kelpReplay.data;
    return { duration: d.duration, samples: d.series.t.length, nodeSamples: d.nodes.t.length,
      nodes: Math.max(...d.nodes.position.map((p) => p.length / 3)), components: d.waves.components.amplitude.length };
  });
  const r = {};
  for (const camera of ['follow', 'underwater']) {
    await page.evaluate((camera) => window.kelpReplay.setCamera(camera), camera);
    const c0 = chromiumCpu();
    r[camera] = await page.evaluate((s) => window.kelpReplay.measureFps(s), seconds);
    const c1 = chromiumCpu();
    r[camera].cpuMs = c0 === null || c1 === null ? NaN : ((c1 - c0) * 1000) / r[camera].frames;
  }
  const size = statSync(file).size;
  console.log(`replay frame rate (headless Chromium, SwiftShader software WebGL, 960x600, this machine under its current load):`);
  console.log(`  run: ${info.duration} s, ${info.samples} log samples, ${info.nodeSamples} node samples, up to ${info.nodes} nodes, ${info.components} wave components; replay.html ${(size / 1e6).toFixed(2)} MB`);
  for (const [camera, m] of Object.entries(r))
    console.log(`  ${camera} camera: ${m.fps.toFixed(1)} frames/s drawn at ${m.pixelRatio} x 960x600 (${m.frames} frames in ${m.seconds.toFixed(1)} s; ` +
      `${m.workMs.toFixed(1)} ms of JS update + render call and ${m.cpuMs.toFixed(0)} ms of CPU in all of Chromium's processes per frame)`);
  try {
    console.log(`  load average ${readFileSync('/proc/loadavg', 'utf8').split(' ').slice(0, 3).join(' ')}`);
  } catch {
    // not Linux
  }
  check(r.follow.frames > 0 && r.underwater.frames > 0, 'the replay draws frames while playing');
  checkClean(problems, 'frame rate');
} finally {
  await browser.close();
}
