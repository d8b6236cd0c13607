// At the node sample of peak tension, the segment carrying it is drawn in the legend's top
// colour: the colour the page set for it, and the screenshot's pixels there (the tether is unlit
// and unfogged; the sea, vehicles and overlay are hidden for this picture). The legend's bottom
// colour differs from its top (the scale is not flat).
// usage: node tension_colour.mjs path/to/replay.html
import { launch, open, checkClean, check, fail, replayFile, projectNED, closestColourNear } from './lib.mjs';

const file = replayFile();
const browser = await launch();
try {
  const { page, problems } = await open(browser, file, 't=0&paused=1&camera=follow');
  const nodes = await page.evaluate(() => window.kelpReplay.data.nodes);
  let peak = -Infinity, at = -1, seg = -1;
  nodes.tension.forEach((row, i) => row.forEach((v, s) => { if (v > peak) { peak = v; at = i; seg = s; } }));
  if (at < 0) fail('the data has no tether tensions');
  const t = nodes.t[at];
  await page.evaluate((t) => window.kelpReplay.setTime(t), t);
  const r = await page.evaluate((seg) => ({
    tension: window.kelpReplay.segmentTension(seg), colour: window.kelpReplay.segmentColour(seg),
    top: window.kelpReplay.legendTopColour(), bottom: window.kelpReplay.legendBottomColour(),
    scale: window.kelpReplay.tensionScale, count: window.kelpReplay.segmentCount(),
  }), seg);
  console.log(`peak tension ${peak} N in segment ${seg} of ${r.count} at t = ${t} s; legend ${r.scale.min}…${r.scale.max} N`);
  check(Math.abs(r.tension - peak) <= 1e-9, `the page shows segment ${seg}'s tension at t = ${t} s as ${r.tension} N (the data: ${peak} N)`);
  check(r.colour === r.top, `the segment of peak tension is drawn in ${r.colour}, the legend's top colour ${r.top}`);
  check(r.bottom !== r.top, `the legend's bottom colour ${r.bottom} is not its top colour`);
  // The pixels: the segment's midpoint in the screenshot
  await page.evaluate(() => window.kelpReplay.setLayers({ overlay: false, sea: false, boat: false, rov: false, target: false }));
  const cam = await page.evaluate(() => window.kelpReplay.camera());
  const p = nodes.position[at];
  const midpoint = [0, 1, 2].map((k) => (p[3 * seg + k] + p[3 * seg + 3 + k]) / 2);
  const px = projectNED(cam, midpoint);
  check(px[0] >= 0 && px[1] >= 0 && px[0] < cam.width && px[1] < cam.height,
    `the segment's midpoint is in the follow camera's picture, at (${px.map((v) => v.toFixed(1))}) px`);
  const shot = await page.screenshot({ type: 'png' });
  const c = await closestColourNear(page, shot, px, 3, r.top);
  check(c.distance <= 3, `the screenshot shows ${c.colour && c.colour.join(',')} at (${c.at}) near the segment's midpoint (${px.map((v) => v.toFixed(1))}) px: the legend's top colour ${r.top} within 3/255`);
  checkClean(problems, 'tension colour');
} finally {
  await browser.close();
}
