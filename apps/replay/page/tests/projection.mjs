// The vehicles and the tether are drawn at their logged positions: at a log sample (t = 40 s)
// and between samples (the test interpolates the log itself), for the follow and underwater
// cameras, the logged boat, ROV and middle tether node, projected here with the camera the page
// reports, land within 2 px of the page's own projections; and hiding each of them changes the
// screenshot around that point (a vehicle's changed pixels surround it; the tether's pass within
// 3 px of the mid node): it is drawn there.
// usage: node projection.mjs path/to/replay.html
import { launch, open, checkClean, check, fail, replayFile, projectNED, interp, screenshotDiff } from './lib.mjs';

const file = replayFile();
const browser = await launch();
try {
  for (const camera of ['follow', 'underwater']) {
    for (const t of [40, 23.45]) {
      const { page, problems } = await open(browser, file, `t=${t}&paused=1&camera=${camera}`);
      const { data, cam, proj } = await page.evaluate(() => ({
        data: { series: window.kelpReplay.data.series, nodes: window.kelpReplay.data.nodes },
        cam: window.kelpReplay.camera(), proj: window.kelpReplay.projected(),
      }));
      const s = data.series;
      const logged = (v) => ['n', 'e', 'd'].map((k) => interp(s.t, s[v][k], t));
      // the middle node of the node sample(s) around t (the page interpolates between samples of
      // the same node count)
      const nt = data.nodes.t;
      let i = 0;
      while (i + 1 < nt.length && nt[i + 1] <= t) i++;
      const p0 = data.nodes.position[i], p1 = data.nodes.position[i + 1];
      const mid = Math.floor(p0.length / 3 / 2);
      const u = p1 && p1.length === p0.length && nt[i] !== t ? (t - nt[i]) / (nt[i + 1] - nt[i]) : 0;
      const node = [0, 1, 2].map((k) => p0[3 * mid + k] + (u ? (p1[3 * mid + k] - p0[3 * mid + k]) * u : 0));
      if (proj.midNode.index !== mid) fail(`the page's middle node is ${proj.midNode.index}, not ${mid}`);
      const points = [];
      for (const [name, ned, got] of [['boat', logged('boat'), proj.boat], ['rov', logged('rov'), proj.rov], ['mid node', node, proj.midNode]]) {
        const [x, y] = projectNED(cam, ned);
        const err = Math.hypot(x - got.x, y - got.y);
        check(err <= 2, `${camera} camera, t = ${t} s: the ${name} at NED (${ned.map((v) => v.toFixed(3)).join(', ')}) projects to ` +
          `(${x.toFixed(1)}, ${y.toFixed(1)}) px, the page draws it at (${got.x.toFixed(1)}, ${got.y.toFixed(1)}) px (${err.toFixed(3)} px apart)`);
        points.push([x, y]);
      }
      // drawn there: hiding the object changes pixels next to its projected point
      if (t === 40) {
        await page.evaluate(() => window.kelpReplay.setLayers({ overlay: false, sea: false }));
        const all = await page.screenshot({ type: 'png' });
        for (const [k, layer] of [[0, 'boat'], [1, 'rov'], [2, 'tether']]) {
          const [x, y] = points[k];
          if (x < 0 || y < 0 || x > cam.width || y > cam.height) {
            console.log(`(${camera}, ${layer}: out of view, not checked in the screenshot)`);
            continue;
          }
          await page.evaluate((l) => window.kelpReplay.setLayers({ [l]: false }), layer);
          const without = await page.screenshot({ type: 'png' });
          await page.evaluate((l) => window.kelpReplay.setLayers({ [l]: true }), layer);
          const d = await screenshotDiff(page, all, without, [points[k]]);
          const near = d.nearest[0], box = d.boxes[0];
          if (layer === 'tether') { // a line through the node: drawn within 3 px of it
            check(near !== null && near <= 3, `${camera} camera: hiding the tether changes the screenshot ${near === null ? 'nowhere near' : `${near.toFixed(1)} px from`} the mid node's projected point`);
          } else { // a body around its origin (which may lie between its parts, as the boat's)
            const inside = box && x >= box[0] - 2 && x <= box[2] + 2 && y >= box[1] - 2 && y <= box[3] + 2;
            check(inside, `${camera} camera: hiding the ${layer} changes the screenshot around its projected point ` +
              `(${x.toFixed(1)}, ${y.toFixed(1)}) px: changed pixels ${box ? `[${box[0]}, ${box[2]}] x [${box[1]}, ${box[3]}]` : 'none near'}`);
          }
        }
      }
      checkClean(problems, `${camera} camera at t = ${t} s`);
      await page.close();
    }
  }
} finally {
  await browser.close();
}
