// A fleet run's replay (data version 2): the page loads with no console error and no network
// request, and every vehicle, point mass, anchor and tether is drawn where the run logged it. For
// the follow camera (which keeps the whole fleet in the picture) at a log sample and between
// samples, and for the underwater camera, each part's logged position (a line's middle node),
// projected here with the camera the page reports, lands within 2 px of the page's own projection;
// in the follow view at the log sample, every part is in the picture and hiding it changes the
// screenshot around that point (a body's changed pixels surround it, a line's pass within 3 px of
// its middle node). Each line is drawn with one segment fewer than its logged nodes, and the HUD
// has a row per vehicle, point mass and line. Then the replay plays.
// usage: node fleet.mjs path/to/replay.html [more replay.html ...]
import { existsSync } from 'node:fs';
import { resolve } from 'node:path';
import { launch, open, checkClean, check, fail, projectNED, interp, screenshotDiff } from './lib.mjs';

const files = process.argv.slice(2).filter((f) => f.length > 0);
if (!files.length) fail('usage: node fleet.mjs path/to/replay.html [more ...]');
for (const f of files) if (!existsSync(f)) fail(`${f} does not exist (the fixture run did not write it?)`);

// The logged node positions of a line at t, as the page interpolates them (linear between two
// snapshots of the same node count, else the earlier snapshot): flat n, e, d.
function nodesAt(nodes, t) {
  const nt = nodes.t;
  let i = 0;
  while (i + 1 < nt.length && nt[i + 1] <= t) i++;
  const p0 = nodes.position[i], p1 = nodes.position[i + 1];
  const u = p1 && p1.length === p0.length && nt[i] !== t && t > nt[i] ? (t - nt[i]) / (nt[i + 1] - nt[i]) : 0;
  return p0.map((v, k) => v + (u ? (p1[k] - v) * u : 0));
}

const browser = await launch();
try {
  for (const file of files.map((f) => resolve(f))) {
    console.log(`-- ${file}`);
    for (const [camera, t] of [['follow', 10], ['follow', 13.45], ['underwater', 10]]) {
      const { page, problems } = await open(browser, file, `t=${t}&paused=1&camera=${camera}`);
      const { data, cam, proj, rows, segments } = await page.evaluate(() => {
        const r = window.kelpReplay;
        const d = r.data;
        return {
          data: d, cam: r.camera(), proj: r.projected(),
          rows: document.querySelectorAll('#hud-table td:first-child').length,
          segments: Object.fromEntries(d.tethers.map((l) => [l.name, r.segmentCount(l.name)])),
        };
      });
      if (data.version !== 2 || !data.vehicles) fail(`${file} holds no fleet (version ${data.version})`);
      const s = data.series;
      const at = (body) => ['n', 'e', 'd'].map((k) => interp(s.t, body[k], t));
      const parts = []; // [layer, what, logged NED, the page's projection]
      for (const v of data.vehicles) parts.push([`vehicle:${v.name}`, `vehicle ${v.name}`, at(v), proj.vehicles[v.name]]);
      for (const m of data.point_masses) parts.push([`point_mass:${m.name}`, `point mass ${m.name}`, at(m), proj.point_masses[m.name]]);
      for (const a of data.anchors) parts.push([`anchor:${a.name}`, `anchor ${a.name}`, a.position, proj.anchors[a.name]]);
      for (const l of data.tethers) {
        const p = nodesAt(l.nodes, t);
        const count = p.length / 3, mid = Math.floor(count / 2);
        const got = proj.tethers[l.name];
        if (!got || got.index !== mid) fail(`${l.name}: the page's middle node is ${got && got.index}, not ${mid}`);
        parts.push([`tether:${l.name}`, `line ${l.name} (middle node)`, [p[3 * mid], p[3 * mid + 1], p[3 * mid + 2]], got]);
        check(segments[l.name] === count - 1, `t = ${t} s: line ${l.name} is drawn with ${segments[l.name]} segments through its ${count} logged nodes`);
      }
      check(parts.length >= 3, `${camera} camera, t = ${t} s: ${data.vehicles.length} vehicles, ${data.point_masses.length} point masses, ` +
        `${data.anchors.length} anchors, ${data.tethers.length} lines`);
      for (const [, what, ned, got] of parts) {
        const [x, y] = projectNED(cam, ned);
        const err = Math.hypot(x - got.x, y - got.y);
        check(err <= 2, `${camera} camera, t = ${t} s: the ${what} at NED (${ned.map((v) => v.toFixed(3)).join(', ')}) projects to ` +
          `(${x.toFixed(1)}, ${y.toFixed(1)}) px, the page draws it at (${got.x.toFixed(1)}, ${got.y.toFixed(1)}) px (${err.toFixed(3)} px apart)`);
      }
      if (camera === 'follow' && t === 10) {
        check(rows === data.vehicles.length + data.point_masses.length + data.tethers.length,
          `the HUD has a row for each of the ${rows} vehicles, point masses and lines`);
        await page.evaluate(() => window.kelpReplay.setLayers({ overlay: false, sea: false }));
        const all = await page.screenshot({ type: 'png' });
        for (const [layer, what, ned] of parts) {
          const [x, y] = projectNED(cam, ned);
          if (!(x >= 0 && y >= 0 && x <= cam.width && y <= cam.height))
            fail(`the follow camera leaves the ${what} out of the picture (${x.toFixed(1)}, ${y.toFixed(1)}) px`);
          await page.evaluate((l) => window.kelpReplay.setLayers({ [l]: false }), layer);
          const without = await page.screenshot({ type: 'png' });
          await page.evaluate((l) => window.kelpReplay.setLayers({ [l]: true }), layer);
          const d = await screenshotDiff(page, all, without, [[x, y]]);
          const near = d.nearest[0], box = d.boxes[0];
          if (layer.startsWith('tether:')) {
            check(near !== null && near <= 3, `hiding the ${what} changes the screenshot ${near === null ? 'nowhere near' : `${near.toFixed(1)} px from`} its projected point`);
          } else {
            const inside = box && x >= box[0] - 2 && x <= box[2] + 2 && y >= box[1] - 2 && y <= box[3] + 2;
            check(inside, `hiding the ${what} changes the screenshot around its projected point (${x.toFixed(1)}, ${y.toFixed(1)}) px: ` +
              `changed pixels ${box ? `[${box[0]}, ${box[2]}] x [${box[1]}, ${box[3]}]` : 'none near'}`);
          }
        }
      }
      checkClean(problems, `${camera} camera at t = ${t} s`);
      await page.close();
    }
    // It plays: time advances, frames are drawn, nothing complains.
    const { page, problems } = await open(browser, file, 'camera=follow&speed=4');
    const start = await page.evaluate(() => ({ time: window.kelpReplay.time, frames: window.kelpReplay.frames }));
    await page.waitForFunction((f) => window.kelpReplay.frames > f + 5, { timeout: 120000 }, start.frames);
    const later = await page.evaluate(() => window.kelpReplay.time);
    check(later > start.time, `the fleet's replay plays (t ${start.time.toFixed(2)} -> ${later.toFixed(2)} s)`);
    checkClean(problems, 'playing');
    await page.close();
  }
} finally {
  await browser.close();
}
