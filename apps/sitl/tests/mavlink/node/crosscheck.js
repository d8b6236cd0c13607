#!/usr/bin/env node
// Cross-check of kelp's MAVLink codec against node-mavlink, an independent implementation
// (npm package; its definitions are generated from upstream MAVLink's XML).
//
//   node crosscheck.js /path/to/kelp-mavlink-vectors [SEED] [COUNT]
//
// 1. kelp -> node-mavlink: kelp encodes COUNT random instances of every message it knows (the
//    first all zeros); node-mavlink's splitter must accept every frame (CRC with its own
//    CRC_EXTRA table) and its decoder must give the same values (floats bit for bit).
// 2. node-mavlink -> kelp: node-mavlink encodes random instances; kelp must accept and decode
//    them to the same values.
// Fields node-mavlink has and kelp has not (extensions that upstream MAVLink added after
// ArduPilot's fork: SYS_STATUS, TIMESYNC) are reported, kept zero in (2) and checked to be zero
// in (1); with them non-zero kelp must reject the frame as too long (its documented policy).
// Exits 1 on any difference, or when node-mavlink is not installed.
'use strict';

const path = require('path');
const { spawnSync } = require('child_process');

let mav;
let mavVersion = '?';
try {
  mav = require('node-mavlink');
  mavVersion = require('node-mavlink/package.json').version;
} catch (e) {
  console.error(`crosscheck: FAILED: cannot load node-mavlink from ${path.join(__dirname, 'node_modules')}` +
                ` (${e.message.split('\n')[0]}).\nRun scripts/install-deps, which runs` +
                ` 'npm ci --no-audit --no-fund' in ${__dirname}.`);
  process.exit(1);
}

const tool = process.argv[2];
const seed = Number(process.argv[3] || 20250721);
const count = Number(process.argv[4] || 40);
if (!tool) {
  console.error('usage: node crosscheck.js /path/to/kelp-mavlink-vectors [SEED] [COUNT]');
  process.exit(2);
}

const REGISTRY = { ...mav.minimal.REGISTRY, ...mav.common.REGISTRY };
let failures = 0;
const fail = (msg) => {
  failures++;
  if (failures <= 30) console.error('MISMATCH: ' + msg);
};

// ---- helpers ---------------------------------------------------------------------------------
const snakeToCamel = (s) => s.replace(/_([a-z0-9])/g, (_, c) => c.toUpperCase());
function nodeField(clazz, kelpName) {
  const camel = snakeToCamel(kelpName);
  // node-mavlink names COMMAND_LONG's params _param1.._param7.
  return clazz.FIELDS.find((f) => f.name === camel || f.name === '_' + camel);
}
const baseType = (t) => (t === 'uint8_t_mavlink_version' ? 'uint8_t' : t);

function floatBits(x) {
  const b = Buffer.alloc(4);
  b.writeFloatLE(x, 0);
  return b.readUInt32LE(0).toString(16).padStart(8, '0');
}
function doubleBits(x) {
  const b = Buffer.alloc(8);
  b.writeDoubleLE(x, 0);
  return b.readBigUInt64LE(0).toString(16).padStart(16, '0');
}
function floatFromBits(hex) {
  const b = Buffer.alloc(4);
  b.writeUInt32LE(parseInt(hex, 16), 0);
  return b.readFloatLE(0);
}

// node value -> the JSON form kelp-mavlink-vectors uses.
function canonical(field, value) {
  const t = baseType(field.type);
  if (t === 'float') return floatBits(value);
  if (t === 'double') return doubleBits(value);
  if (t === 'int64_t' || t === 'uint64_t') return BigInt(value).toString();
  if (t === 'char[]' || t === 'char') return String(value);
  return Number(value);
}

function isZero(field, value) {
  const t = baseType(field.type);
  if (t.endsWith('[]')) return t === 'char[]' ? value === '' : value.every((v) => Number(v) === 0);
  return Number(value) === 0;
}

// Seeded PRNG (mulberry32) so a failure can be reproduced.
let state = seed >>> 0;
function rand32() {
  state = (state + 0x6d2b79f5) >>> 0;
  let t = state;
  t = Math.imul(t ^ (t >>> 15), t | 1);
  t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
  return (t ^ (t >>> 14)) >>> 0;
}
function randomValue(field) {
  const t = baseType(field.type);
  switch (t) {
    case 'uint8_t': return rand32() & 0xff;
    case 'int8_t': return ((rand32() & 0xff) << 24) >> 24;
    case 'uint16_t': return rand32() & 0xffff;
    case 'int16_t': return ((rand32() & 0xffff) << 16) >> 16;
    case 'uint32_t': return rand32();
    case 'int32_t': return rand32() | 0;
    case 'uint64_t': return (BigInt(rand32()) << 32n) | BigInt(rand32());
    case 'int64_t': return BigInt.asIntN(64, (BigInt(rand32()) << 32n) | BigInt(rand32()));
    case 'float': {
      for (;;) {
        const v = floatFromBits(rand32().toString(16));
        if (Number.isFinite(v)) return v;
      }
    }
    case 'double': {
      const b = Buffer.alloc(8);
      for (;;) {
        b.writeUInt32LE(rand32(), 0);
        b.writeUInt32LE(rand32(), 4);
        const v = b.readDoubleLE(0);
        if (Number.isFinite(v)) return v;
      }
    }
    case 'char[]': {
      const n = rand32() % (field.length + 1);
      let s = '';
      for (let i = 0; i < n; i++) s += String.fromCharCode(0x20 + (rand32() % 95));
      return s;
    }
    default: throw new Error(`no random value for type ${field.type}`);
  }
}
function zeroValue(field) {
  const t = baseType(field.type);
  if (t === 'int64_t' || t === 'uint64_t') return 0n;
  if (t === 'char[]') return '';
  if (t.endsWith('[]')) return new Array(field.length).fill(0);
  return 0;
}

function runTool(args, input) {
  const r = spawnSync(tool, args, { input, encoding: 'utf8', maxBuffer: 64 << 20 });
  if (r.error || r.status !== 0) {
    console.error(`crosscheck: FAILED: ${tool} ${args.join(' ')}: ${r.error || r.stderr}`);
    process.exit(1);
  }
  return r.stdout.split('\n').filter((l) => l.length > 0).map((l) => JSON.parse(l));
}

function splitAndParse(buffer) {
  return new Promise((resolve, reject) => {
    const splitter = new mav.MavLinkPacketSplitter();
    const parser = splitter.pipe(new mav.MavLinkPacketParser());
    const packets = [];
    parser.on('data', (p) => packets.push(p));
    parser.on('end', () => resolve({ packets, splitter }));
    parser.on('error', reject);
    splitter.end(buffer);
  });
}

const notes = new Set();

// ---- 1. kelp -> node-mavlink -----------------------------------------------------------------
async function kelpToNode() {
  const vectors = runTool(['encode', String(seed), String(count)]);
  const buffer = Buffer.concat(vectors.map((v) => Buffer.from(v.hex, 'hex')));
  const { packets, splitter } = await splitAndParse(buffer);
  if (packets.length !== vectors.length || splitter.invalidPackages !== 0 ||
      splitter.unknownPackagesCount !== 0) {
    fail(`kelp -> node: ${vectors.length} frames sent, node-mavlink accepted ${packets.length}` +
         ` (invalid ${splitter.invalidPackages}, unknown ${splitter.unknownPackagesCount})`);
    return 0;
  }
  const names = new Set();
  vectors.forEach((v, i) => {
    const p = packets[i];
    const where = `kelp -> node ${v.name} #${i}`;
    names.add(v.name);
    const h = p.header;
    if (p.protocol.name !== 'MAV_V2' || h.msgid !== v.msgid || h.seq !== v.seq || h.sysid !== v.sysid ||
        h.compid !== v.compid || h.payloadLength !== v.hex.length / 2 - 12) {
      fail(`${where}: header ${JSON.stringify(h)}`);
      return;
    }
    const clazz = REGISTRY[v.msgid];
    if (!clazz || clazz.MSG_NAME !== v.name) {
      fail(`${where}: node-mavlink has no ${v.name} with id ${v.msgid}`);
      return;
    }
    const data = p.protocol.data(p.payload, clazz);
    for (const [name, expected] of Object.entries(v.fields)) {
      const f = nodeField(clazz, name);
      if (!f) {
        fail(`${where}: node-mavlink has no field ${name}`);
        continue;
      }
      const got = canonical(f, data[f.name]);
      if (got !== expected) fail(`${where}.${name}: kelp sent ${expected}, node-mavlink read ${got}`);
    }
    for (const f of clazz.FIELDS) {
      if (Object.keys(v.fields).some((n) => nodeField(clazz, n) === f)) continue;
      notes.add(`${v.name}.${f.name} (${f.type}) exists in node-mavlink only`);
      if (!isZero(f, data[f.name])) fail(`${where}: node-mavlink read ${f.name} = ${data[f.name]}`);
    }
  });
  console.log(`kelp -> node-mavlink: ${vectors.length} frames of ${names.size} messages, ` +
              'all accepted and decoded to the same values');
  return vectors;
}

// ---- 2. node-mavlink -> kelp -----------------------------------------------------------------
function nodeToKelp(kelpVectors) {
  // kelp's field names per message id, from its own output.
  const kelpFields = new Map();
  for (const v of kelpVectors) kelpFields.set(v.msgid, { name: v.name, fields: Object.keys(v.fields) });

  const cases = [];
  for (const [msgid, info] of kelpFields) {
    const clazz = REGISTRY[msgid];
    const known = clazz.FIELDS.filter((f) => info.fields.some((n) => nodeField(clazz, n) === f));
    const extra = clazz.FIELDS.filter((f) => !known.includes(f));
    for (let k = 0; k < count + (extra.length ? 1 : 0); k++) {
      const msg = new clazz();
      const allZero = k === 0;
      const extraNonZero = k === count;  // one frame with node-mavlink's extra fields set
      for (const f of known) msg[f.name] = allZero || (k % 3 === 2 && rand32() % 2) ? zeroValue(f) : randomValue(f);
      for (const f of extra) msg[f.name] = extraNonZero ? randomValue(f) : zeroValue(f);
      if (extraNonZero) extra.forEach((f) => { if (isZero(f, msg[f.name])) msg[f.name] = 1; });
      const seq = rand32() & 0xff;
      const sysid = rand32() & 0xff;
      const compid = rand32() & 0xff;
      const frame = new mav.MavLinkProtocolV2(sysid, compid).serialize(msg, seq);
      cases.push({ clazz, info, known, msg, seq, sysid, compid, frame, expectReject: extraNonZero });
    }
  }
  const results = runTool(['decode'], cases.map((c) => c.frame.toString('hex')).join('\n') + '\n');
  if (results.length !== cases.length) {
    fail(`node -> kelp: ${cases.length} frames, ${results.length} answers`);
    return;
  }
  let accepted = 0;
  let rejectedAsTooLong = 0;
  let lenZero = 0;
  cases.forEach((c, i) => {
    const r = results[i];
    const where = `node -> kelp ${c.info.name} #${i}`;
    if (c.expectReject) {
      // Upstream extension fields set: LEN exceeds the length kelp knows.
      if (r.ok || r.stats.bad_length !== 1) fail(`${where}: expected a bad_length rejection, got ${JSON.stringify(r)}`);
      else rejectedAsTooLong++;
      return;
    }
    if (!r.ok) {
      fail(`${where}: rejected ${c.frame.toString('hex')}: ${JSON.stringify(r.stats)}`);
      return;
    }
    if (r.len === 0) lenZero++;
    if (r.name !== c.info.name || r.seq !== c.seq || r.sysid !== c.sysid || r.compid !== c.compid ||
        r.len !== c.frame.length - 12 || r.version !== 2) {
      fail(`${where}: header ${JSON.stringify(r)}`);
      return;
    }
    for (const name of c.info.fields) {
      const f = nodeField(c.clazz, name);
      const expected = canonical(f, c.msg[f.name]);
      if (r.fields[name] !== expected) fail(`${where}.${name}: node-mavlink sent ${expected}, kelp read ${r.fields[name]}`);
    }
    accepted++;
  });
  console.log(`node-mavlink -> kelp: ${accepted} frames accepted and decoded to the same values` +
              ` (${lenZero} all-zero payloads sent by node-mavlink with LEN 0);` +
              ` ${rejectedAsTooLong} frames with upstream-only extension fields rejected as too long`);
}

(async () => {
  console.log(`node ${process.version}, node-mavlink ${mavVersion}, seed ${seed}, ${count} instances per message`);
  const vectors = await kelpToNode();
  if (vectors) nodeToKelp(vectors);
  for (const n of [...notes].sort()) console.log(`note: ${n} (not in ArduPilot's fork; compared as zero)`);
  if (failures > 0) {
    console.error(`crosscheck: FAILED with ${failures} mismatches`);
    process.exit(1);
  }
  console.log('crosscheck: passed');
})().catch((e) => {
  console.error('crosscheck: FAILED: ' + (e.stack || e));
  process.exit(1);
});
