// Independent check of kelp's ROS 2 bags (run by CTest: ros2_mcap_node_check).
//
//   node check_bags.mjs <dir or file> ...
//
// For every .mcap file found (directories are searched recursively):
//   - the official MCAP library (@mcap/core) reads it through its index (McapIndexedReader: footer,
//     summary and its CRC, chunk indexes, message indexes) with chunk CRCs validated, and once more
//     front to back (McapStreamReader, CRCs validated); the data section's CRC is recomputed;
//   - the ros2 profile: profile "ros2", "cdr" channels with offered_qos_profiles, "ros2msg"
//     schemas;
//   - every message is decoded by Foxglove's ROS 2 CDR reader (@foxglove/rosmsg2-serialization)
//     with the definitions parsed from the file's own schema (@foxglove/rosmsg, ros2 mode), using
//     every byte, and its header stamp equals its log time;
//   - beside a reference.csv (the samples in kelp's own frames, NED/FRD, at full precision, from
//     tests/ros2/test_ros2_bag.cpp) poses, velocities, the IMU and the end wrenches are recomputed
//     here in ROS's frames (REP 103: ENU world, FLU body) and compared to 1e-9;
//   - beside a timeseries.csv only (kelp-tethered-pair's and kelp-sitl's runs) each logged sample is
//     compared with the CSV's 6 significant digits: both odometries' positions, attitudes (from
//     the CSV's Euler angles) and logged body velocities, the magnitude of the tether's force at
//     each end (the CSV's tensions) and every thruster's command and thrust.
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { crc32 } from "@foxglove/crc";
import fs from "node:fs";
import path from "node:path";

let failures = 0;
function fail(file, what) {
  failures++;
  console.error(`FAIL ${file}: ${what}`);
}

function findBags(p) {
  if (!fs.existsSync(p)) return [];
  if (fs.statSync(p).isFile()) return [p];
  return fs.readdirSync(p).flatMap((e) => {
    const q = path.join(p, e);
    if (fs.statSync(q).isDirectory()) return findBags(q);
    return e.endsWith(".mcap") ? [q] : [];
  });
}

function readCsv(file) {
  const lines = fs.readFileSync(file, "utf8").trim().split("\n");
  const head = lines[0].split(",");
  return lines.slice(1).map((l) => {
    const v = l.split(",").map(Number);
    return Object.fromEntries(head.map((h, i) => [h, v[i]]));
  });
}

// --- ROS's frames, worked out here from REP 103 (not from kelp's code) -------------------------
// Rotation matrix (row-major 3×3) of a unit quaternion (w, x, y, z).
function rot(w, x, y, z) {
  return [
    [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
    [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
    [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
  ];
}
const mul = (A, B) => A.map((r) => [0, 1, 2].map((j) => r[0] * B[0][j] + r[1] * B[1][j] + r[2] * B[2][j]));
const mv = (A, v) => A.map((r) => r[0] * v[0] + r[1] * v[1] + r[2] * v[2]);
const tr = (A) => [0, 1, 2].map((i) => [0, 1, 2].map((j) => A[j][i]));
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const sub = (a, b) => a.map((x, i) => x - b[i]);
const add = (a, b) => a.map((x, i) => x + b[i]);
// World: north, east, down → east, north, up. Body: forward, starboard, down → forward, left, up.
const enu = (v) => [v[1], v[0], -v[2]];
const flu = (v) => [v[0], -v[1], -v[2]];
const ENU_NED = [[0, 1, 0], [1, 0, 0], [0, 0, -1]];
const FRD_FLU = [[1, 0, 0], [0, -1, 0], [0, 0, -1]];

function stampNs(t) {
  const sec = Math.floor(t);
  let ns = Math.round((t - sec) * 1e9);
  return BigInt(sec) * 1000000000n + BigInt(ns);
}

function near(file, what, got, want, tol) {
  for (let i = 0; i < want.length; i++) {
    if (!(Math.abs(got[i] - want[i]) <= tol)) {
      fail(file, `${what}[${i}]: ${got[i]} vs ${want[i]} (tolerance ${tol})`);
      return false;
    }
  }
  return true;
}
const v3 = (m) => [m.x, m.y, m.z];
// A value against the CSV's 6 significant digits (absolute 6e-6 below 1).
function csvNear(file, what, got, want) {
  for (let i = 0; i < want.length; i++) {
    if (!(Math.abs(got[i] - want[i]) <= 6e-6 * Math.max(1, Math.abs(want[i])))) {
      fail(file, `${what}[${i}]: ${got[i]} vs CSV ${want[i]}`);
      return;
    }
  }
}
// Rotation matrix body → NED of zyx Euler angles (Fossen 2021, eq. 2.18: R = Rz(ψ) Ry(θ) Rx(φ)).
function rotZYX(phi, theta, psi) {
  const [cf, sf, ct, st, cp, sp] = [Math.cos(phi), Math.sin(phi), Math.cos(theta), Math.sin(theta),
    Math.cos(psi), Math.sin(psi)];
  return [
    [cp * ct, -sp * cf + cp * st * sf, sp * sf + cp * cf * st],
    [sp * ct, cp * cf + sf * st * sp, -cp * sf + st * sp * cf],
    [-st, ct * sf, ct * cf],
  ];
}

// A fleet's bag beside its timeseries.csv (columns `<part>.<quantity>`): every vehicle's
// odometry (position, attitude from the Euler angles, body velocity), every point mass's /tf
// translation and every tether's end forces (their magnitudes are the CSV's tensions), each
// logged sample to the CSV's 6 significant digits. Returns the samples compared.
function checkFleetCsv(file, csv, byTopic) {
  const rows = readCsv(csv);
  const head = Object.keys(rows[0] ?? {});
  const parts = (suffix) => head.filter((h) => h.endsWith(suffix)).map((h) => h.slice(0, -suffix.length));
  const vehicles = parts(".roll");
  const tethers = parts(".tension_start");
  const masses = parts(".x").filter((p) => !vehicles.includes(p));
  const stamps = [...(byTopic.get("/clock")?.keys() ?? [])];
  let compared = 0;
  for (const name of vehicles) {
    for (const topic of [`/${name}/odom`, `/${name}/imu`]) {
      if (!byTopic.has(topic)) fail(file, `no messages on ${topic}`);
    }
  }
  for (const name of tethers) {
    if (!byTopic.has(`/${name}/end_forces`)) fail(file, `no messages on /${name}/end_forces`);
  }
  for (const msgs of byTopic.get("/markers")?.values() ?? []) {
    for (const name of tethers) {
      const line = msgs[0].markers.find((k) => k.ns === name && k.type === 4);
      if (!line || line.points.length < 2 || line.colors.length !== line.points.length) {
        fail(file, `/markers: no LINE_STRIP for tether ${name}`);
      }
    }
  }
  const one = (topic, ns) => byTopic.get(topic)?.get(ns);
  for (const r of rows) {
    let ns = stampNs(r.t);
    let best = Infinity;
    for (const s of stamps) {
      const d = Math.abs(Number(s) * 1e-9 - r.t);
      if (d < best) [best, ns] = [d, s];
    }
    const at = `at t = ${r.t}`;
    if (!(best <= 6e-6 * Math.max(1, Math.abs(r.t)))) {
      fail(file, `no sample ${at} (nearest ${best} s away)`);
      continue;
    }
    for (const v of vehicles) {
      const odom = one(`/${v}/odom`, ns);
      if (!odom) {
        fail(file, `/${v}/odom: nothing ${at}`);
        continue;
      }
      const o = odom[0];
      if (o.header.frame_id !== "world" || o.child_frame_id !== `${v}/base_link`) {
        fail(file, `/${v}/odom frames ${o.header.frame_id} → ${o.child_frame_id}`);
      }
      csvNear(file, `/${v}/odom position ${at}`, v3(o.pose.pose.position),
        enu([r[`${v}.x`], r[`${v}.y`], r[`${v}.z`]]));
      const R = rotZYX(r[`${v}.roll`], r[`${v}.pitch`], r[`${v}.yaw`]);
      const q = o.pose.pose.orientation;
      near(file, `/${v}/odom orientation ${at}`, rot(q.w, q.x, q.y, q.z).flat(),
        mul(mul(ENU_NED, R), FRD_FLU).flat(), 3e-5);
      csvNear(file, `/${v}/odom twist ${at}`, v3(o.twist.twist.linear),
        flu([r[`${v}.u`], r[`${v}.v`], r[`${v}.w`]]));
    }
    const tf = one("/tf", ns)?.[0]?.transforms ?? [];
    for (const p of masses) {
      const k = tf.find((x) => x.child_frame_id === p);
      if (!k) {
        fail(file, `/tf: no ${p} ${at}`);
        continue;
      }
      csvNear(file, `/tf ${p} ${at}`, v3(k.transform.translation),
        enu([r[`${p}.x`], r[`${p}.y`], r[`${p}.z`]]));
    }
    for (const l of tethers) {
      const w = one(`/${l}/end_forces`, ns);
      if (!w || w.length !== 2) {
        fail(file, `/${l}/end_forces: not two ends ${at}`);
        continue;
      }
      csvNear(file, `/${l}/end_forces |force| ${at}`,
        w.map((x) => Math.hypot(...v3(x.wrench.force))), [r[`${l}.tension_start`], r[`${l}.tension_end`]]);
    }
    compared++;
  }
  if (compared === 0) fail(file, "timeseries.csv: nothing compared");
  return compared;
}

async function checkBag(file) {
  const buf = fs.readFileSync(file);
  const bytes = new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
  const readable = {
    size: async () => BigInt(bytes.byteLength),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  // Index, summary CRC (checked by Initialize), chunk CRCs (validateCrcs).
  const reader = await McapIndexedReader.Initialize({ readable });
  if (reader.header.profile !== "ros2") fail(file, `profile "${reader.header.profile}"`);
  if (reader.dataSectionCrc !== undefined && reader.dataSectionCrc !== 0) {
    const crc = crc32(bytes.subarray(0, Number(reader.dataEndOffset)));
    if (crc !== reader.dataSectionCrc) fail(file, `data section CRC ${crc} vs ${reader.dataSectionCrc}`);
  } else {
    fail(file, "no data section CRC");
  }
  if (reader.chunkIndexes.length === 0) fail(file, "no chunk index");
  const decoders = new Map();
  for (const [id, ch] of reader.channelsById) {
    const schema = reader.schemasById.get(ch.schemaId);
    if (!schema || schema.encoding !== "ros2msg") fail(file, `${ch.topic}: schema not ros2msg`);
    if (ch.messageEncoding !== "cdr") fail(file, `${ch.topic}: encoding ${ch.messageEncoding}`);
    if (!ch.metadata.get("offered_qos_profiles")) fail(file, `${ch.topic}: no offered_qos_profiles`);
    const text = new TextDecoder().decode(schema.data);
    decoders.set(id, { topic: ch.topic, type: schema.name, reader: new MessageReader(parse(text, { ros2: true })) });
  }

  // Every message, through the index, decoded.
  const byTopic = new Map();
  let count = 0;
  let last = -1n;
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    count++;
    if (m.logTime < last) fail(file, "messages out of log-time order");
    last = m.logTime;
    const d = decoders.get(m.channelId);
    const msg = d.reader.readMessage(m.data);
    if (d.reader.lastReadHadTrailingBytes()) fail(file, `${d.topic}: trailing bytes`);
    const stamp = d.topic === "/clock" ? msg.clock : d.topic === "/tf" ? msg.transforms[0].header.stamp
      : d.topic === "/tether/markers" || d.topic === "/markers" ? msg.markers[0].header.stamp
      : msg.header.stamp;
    const ns = BigInt(stamp.sec) * 1000000000n + BigInt(stamp.nanosec);
    if (ns !== m.logTime) fail(file, `${d.topic}: stamp ${ns} != log time ${m.logTime}`);
    if (!byTopic.has(d.topic)) byTopic.set(d.topic, new Map());
    const t = byTopic.get(d.topic);
    if (!t.has(m.logTime)) t.set(m.logTime, []);
    t.get(m.logTime).push(msg);
  }
  if (BigInt(count) !== reader.statistics.messageCount) {
    fail(file, `read ${count} messages, statistics say ${reader.statistics.messageCount}`);
  }
  // Front to back, CRCs validated: the same messages.
  const stream = new McapStreamReader({ validateCrcs: true });
  stream.append(bytes);
  let streamed = 0;
  for (let r; (r = stream.nextRecord()); ) if (r.type === "Message") streamed++;
  if (!stream.done()) fail(file, "stream reader did not reach the end");
  if (streamed !== count) fail(file, `stream read ${streamed} messages, indexed ${count}`);
  // A fleet's bag (kelp/sim/ros2/fleet.hpp) has one /markers topic and topics per part.
  const fleet = byTopic.has("/markers");
  for (const topic of fleet ? ["/clock", "/tf", "/markers"] : ["/clock", "/tf", "/boat/odom",
    "/rov/odom", "/rov/imu", "/tether/end_forces", "/tether/markers", "/rov/thrusters",
    "/boat/thrusters"]) {
    if (!byTopic.has(topic)) fail(file, `no messages on ${topic}`);
  }
  for (const msgs of byTopic.get("/tether/markers")?.values() ?? []) {
    const line = msgs[0].markers.find((k) => k.ns === "tether");
    if (!line || line.type !== 4 || line.points.length < 2 || line.colors.length !== line.points.length) {
      fail(file, "/tether/markers: no LINE_STRIP with a colour per point");
    }
  }

  const dir = path.dirname(file);
  const one = (topic, ns) => byTopic.get(topic)?.get(ns);
  let compared = 0;
  if (fs.existsSync(path.join(dir, "reference.csv"))) {
    const tol = 1e-9;
    for (const r of readCsv(path.join(dir, "reference.csv"))) {
      const ns = stampNs(r.t);
      const clock = one("/clock", ns);
      if (!clock) {
        fail(file, `no messages at t = ${r.t}`);
        continue;
      }
      const tf = one("/tf", ns)[0].transforms;
      const forces = one("/tether/end_forces", ns);
      for (const [k, who] of [[0, "boat"], [1, "rov"]]) {
        const R = rot(r[`${who}_qw`], r[`${who}_qx`], r[`${who}_qy`], r[`${who}_qz`]);
        const pos = [r[`${who}_n`], r[`${who}_e`], r[`${who}_d`]];
        const vel = [r[`${who}_u`], r[`${who}_v`], r[`${who}_w`]];
        const omega = [r[`${who}_p`], r[`${who}_q`], r[`${who}_r`]];
        const Rros = mul(mul(ENU_NED, R), FRD_FLU);
        const odom = one(`/${who}/odom`, ns)[0];
        if (odom.header.frame_id !== "world" || odom.child_frame_id !== `${who}/base_link`) {
          fail(file, `/${who}/odom frames ${odom.header.frame_id} → ${odom.child_frame_id}`);
        }
        const o = odom.pose.pose.orientation;
        near(file, `/${who}/odom position`, v3(odom.pose.pose.position), enu(pos), tol);
        near(file, `/${who}/odom orientation`, rot(o.w, o.x, o.y, o.z).flat(), Rros.flat(), tol);
        near(file, `/${who}/odom linear`, v3(odom.twist.twist.linear), flu(vel), tol);
        near(file, `/${who}/odom angular`, v3(odom.twist.twist.angular), flu(omega), tol);
        const tfk = tf.find((x) => x.child_frame_id === `${who}/base_link`);
        const q = tfk.transform.rotation;
        near(file, `/tf ${who} translation`, v3(tfk.transform.translation), enu(pos), tol);
        near(file, `/tf ${who} rotation`, rot(q.w, q.x, q.y, q.z).flat(), Rros.flat(), tol);
        // The tether's force on the vehicle, in its body axes, about its origin.
        const F = mv(tr(R), [r[`${who}_fn`], r[`${who}_fe`], r[`${who}_fd`]]);
        const arm = mv(tr(R), sub([r[`${who}_end_n`], r[`${who}_end_e`], r[`${who}_end_d`]], pos));
        const w = forces.find((x) => x.header.frame_id === `${who}/base_link`);
        if (!w) {
          fail(file, `/tether/end_forces: no ${who} end at t = ${r.t}`);
          continue;
        }
        near(file, `/tether/end_forces ${who} force`, v3(w.wrench.force), flu(F), tol);
        near(file, `/tether/end_forces ${who} torque`, v3(w.wrench.torque), flu(cross(arm, F)), tol);
        if (who === "rov") {
          const imu = one("/rov/imu", ns)[0];
          const nuDot = [r.rov_nu_dot_du, r.rov_nu_dot_dv, r.rov_nu_dot_dw];
          // Specific force: the CO's acceleration (body) minus gravity, (0, 0, g) down in NED.
          const f = sub(add(nuDot, cross(omega, vel)), mv(tr(R), [0, 0, r.gravity]));
          const qi = imu.orientation;
          near(file, "/rov/imu orientation", rot(qi.w, qi.x, qi.y, qi.z).flat(), Rros.flat(), tol);
          near(file, "/rov/imu angular_velocity", v3(imu.angular_velocity), flu(omega), tol);
          near(file, "/rov/imu linear_acceleration", v3(imu.linear_acceleration), flu(f), tol);
        }
      }
      const clockNs = BigInt(clock[0].clock.sec) * 1000000000n + BigInt(clock[0].clock.nanosec);
      if (clockNs !== ns) fail(file, `/clock ${clockNs} at ${ns}`);
      compared++;
    }
    if (compared === 0) fail(file, "reference.csv: nothing compared");
  } else if (fleet && fs.existsSync(path.join(dir, "timeseries.csv"))) {
    compared = checkFleetCsv(file, path.join(dir, "timeseries.csv"), byTopic);
  } else if (fs.existsSync(path.join(dir, "timeseries.csv"))) {
    // The CSV's times have 6 significant digits too: each row takes the nearest stamp within that.
    const stamps = [...(byTopic.get("/rov/odom")?.keys() ?? [])];
    for (const r of readCsv(path.join(dir, "timeseries.csv"))) {
      let ns = stampNs(r.t);
      let best = Infinity;
      for (const s of stamps) {
        const d = Math.abs(Number(s) * 1e-9 - r.t);
        if (d < best) [best, ns] = [d, s];
      }
      if (!(best <= 6e-6 * Math.max(1, Math.abs(r.t)))) {
        fail(file, `no sample at t = ${r.t} (nearest ${best} s away)`);
        continue;
      }
      const forces = one("/tether/end_forces", ns) ?? [];
      for (const [who, col] of [["boat", "asv"], ["rov", "auv"]]) {
        const odom = one(`/${who}/odom`, ns);
        if (!odom) {
          fail(file, `/${who}/odom: nothing at t = ${r.t}`);
          continue;
        }
        const at = `at t = ${r.t}`;
        const o = odom[0];
        csvNear(file, `/${who}/odom position ${at}`, v3(o.pose.pose.position),
          enu([r[`${col}_x`], r[`${col}_y`], r[`${col}_z`]]));
        // Attitude: the CSV's zyx Euler angles (6 digits, so ~1e-5 rad) as ROS's rotation.
        const R = rotZYX(r[`${col}_roll`], r[`${col}_pitch`], r[`${col}_yaw`]);
        const q = o.pose.pose.orientation;
        near(file, `/${who}/odom orientation ${at}`, rot(q.w, q.x, q.y, q.z).flat(),
          mul(mul(ENU_NED, R), FRD_FLU).flat(), 3e-5);
        // Body velocities, FRD → FLU: the boat logs u, v and r, the ROV u, v and w.
        const lin = v3(o.twist.twist.linear);
        if (who === "boat") {
          csvNear(file, `/boat/odom twist ${at}`, [lin[0], lin[1], o.twist.twist.angular.z],
            [r.asv_u, -r.asv_v, -r.asv_r]);
        } else {
          csvNear(file, `/rov/odom twist ${at}`, lin, flu([r.auv_u, r.auv_v, r.auv_w]));
        }
        // The tether's force on each vehicle: its magnitude is the CSV's tension at that end.
        const w = forces.find((x) => x.header.frame_id === `${who}/base_link`);
        if (!w) {
          fail(file, `/tether/end_forces: no ${who} end ${at}`);
        } else {
          const F = v3(w.wrench.force);
          csvNear(file, `/tether/end_forces ${who} |force| ${at}`, [Math.hypot(...F)],
            [r[`tension_${col}`]]);
        }
        // Thrusters: velocity = the normalised command, effort = the thrust [N], motor order.
        const th = one(`/${who}/thrusters`, ns);
        const names = who === "boat" ? ["port", "starboard"] : [1, 2, 3, 4, 5, 6, 7, 8];
        if (!th || th[0].effort.length !== names.length) {
          fail(file, `/${who}/thrusters: no ${names.length} thrusters ${at}`);
        } else {
          csvNear(file, `/${who}/thrusters effort ${at}`, Array.from(th[0].effort),
            names.map((n) => r[`${col}_thrust_${n}`]));
          csvNear(file, `/${who}/thrusters velocity ${at}`, Array.from(th[0].velocity),
            names.map((n) => r[`${col}_command_${n}`]));
        }
      }
      compared++;
    }
  }
  const topics = [...byTopic.keys()].map((t) => `${t} ${[...byTopic.get(t).values()].flat().length}`);
  console.log(`ok ${file}: ${count} messages, ${reader.chunkIndexes.length} chunks, ${compared} samples compared (${topics.join(", ")})`);
}

const args = process.argv.slice(2);
if (args.length === 0) {
  console.error("usage: node check_bags.mjs <dir or run.mcap> ...");
  process.exit(2);
}
const bags = args.flatMap(findBags);
if (bags.length === 0) {
  console.error(`FAIL: no run.mcap in ${args.join(" ")}`);
  process.exit(1);
}
for (const b of bags) {
  try {
    await checkBag(b);
  } catch (e) {
    fail(b, e.stack ?? String(e));
  }
}
if (failures) {
  console.error(`${failures} failure(s)`);
  process.exit(1);
}
console.log(`all ${bags.length} bag(s) pass`);
