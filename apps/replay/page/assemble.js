#!/usr/bin/env node
// Assembles the replay page's template (docs/replay.md): page/replay.html with its markers
// /*@KELP_STYLE@*/, /*@KELP_THREE@*/ and /*@KELP_APP@*/ replaced by replay.css, three.js and
// replay.js. The data marker /*@KELP_DATA@*/ is left for the programs (kelp::sim::write_replay).
//
// three.js r160+ ships no UMD build and its three.cjs (r187) only re-exports the ES module, and
// ES modules do not load from file://. So the ES build (three.core.js, three.module.js; the
// exact files npm installed from package-lock.json) is turned into one classic script
// that defines window.THREE: each file's body runs in its own function scope (as a module's
// does, strict mode), its `import {...} from './three.core.js'` becomes a destructuring of the
// core's exports, and its `export {...}` a returned object. The two files are checked to have
// the simple shape this relies on (imports and exports only as whole lines of plain names).
//
// Usage: node assemble.js --page DIR --three DIR --out FILE
'use strict';
const fs = require('fs');
const path = require('path');

function fail(message) {
  process.stderr.write(`apps/replay/page/assemble.js: ${message}\n`);
  process.exit(1);
}

const args = {};
for (let i = 2; i < process.argv.length; i += 2) {
  const key = process.argv[i];
  if (!['--page', '--three', '--out'].includes(key) || i + 1 >= process.argv.length)
    fail('usage: node assemble.js --page DIR --three DIR --out FILE');
  args[key.slice(2)] = process.argv[i + 1];
}
if (!args.page || !args.three || !args.out)
  fail('usage: node assemble.js --page DIR --three DIR --out FILE');

function read(file) {
  try {
    return fs.readFileSync(file, 'utf8');
  } catch (e) {
    fail(`cannot read ${file}: ${e.message}`);
  }
}

// `{ a, b as c }` -> [[a, a], [b, c]] (local name, exported name).
function names(list, file) {
  return list
    .split(',')
    .map((s) => s.trim())
    .filter((s) => s.length > 0)
    .map((s) => {
      const m = /^([A-Za-z_$][\w$]*)(?:\s+as\s+([A-Za-z_$][\w$]*))?$/.exec(s);
      if (!m) fail(`${file}: cannot read the name "${s}" of an import or export`);
      return [m[1], m[2] || m[1]];
    });
}

// The body of an ES module as a function expression returning its exports. `imports` maps a
// module specifier to the JS expression holding that module's exports.
function wrapModule(file, imports) {
  const source = read(file);
  const lines = source.split('\n');
  const body = [];
  const prologue = [];
  const exported = [];
  for (const line of lines) {
    let m;
    if ((m = /^import\s*\{([^}]*)\}\s*from\s*'([^']+)';\s*$/.exec(line))) {
      if (!(m[2] in imports)) fail(`${file}: imports from ${m[2]}, which is not bundled`);
      const pairs = names(m[1], file).map(([from, as]) => (from === as ? from : `${from}: ${as}`));
      prologue.push(`const { ${pairs.join(', ')} } = ${imports[m[2]]};`);
    } else if ((m = /^export\s*\{([^}]*)\}\s*from\s*'([^']+)';\s*$/.exec(line))) {
      if (!(m[2] in imports)) fail(`${file}: re-exports from ${m[2]}, which is not bundled`);
      for (const [from, as] of names(m[1], file)) exported.push(`${as}: ${imports[m[2]]}.${from}`);
    } else if ((m = /^export\s*\{([^}]*)\};\s*$/.exec(line))) {
      for (const [local, as] of names(m[1], file)) exported.push(local === as ? local : `${as}: ${local}`);
    } else {
      if (/^\s*(import|export)\b/.test(line)) fail(`${file}: an import or export this script cannot bundle: ${line.slice(0, 80)}`);
      body.push(line);
    }
  }
  if (/\bimport\.meta\b/.test(source)) fail(`${file}: uses import.meta, which a classic script lacks`);
  return `(function () {\n'use strict';\n${prologue.join('\n')}\n${body.join('\n')}\nreturn { ${exported.join(', ')} };\n})()`;
}

// A script's text may not close its element or open an HTML comment inside it.
function checkScript(text, what) {
  if (/<\/script/i.test(text)) fail(`${what} contains "</script", which would end its script element`);
  if (text.includes('<!--')) fail(`${what} contains "<!--", which HTML parses specially in a script`);
  return text;
}

const threeDir = args.three;
const pkg = JSON.parse(read(path.join(threeDir, '..', 'package.json')));
const core = wrapModule(path.join(threeDir, 'three.core.js'), {});
const main = wrapModule(path.join(threeDir, 'three.module.js'), { './three.core.js': '__kelpThreeCore' });
const three = checkScript(
  `// three.js ${pkg.version} (MIT, https://threejs.org; see its LICENSE in node_modules/three), ` +
    `its ES build wrapped as a classic script by kelp's apps/replay/page/assemble.js\n` +
    `(function () {\n'use strict';\nconst __kelpThreeCore = ${core};\nconst __kelpThreeMain = ${main};\n` +
    `window.THREE = Object.freeze(Object.assign({}, __kelpThreeCore, __kelpThreeMain));\n})();\n`,
  'three.js'
);

const page = read(path.join(args.page, 'replay.html'));
const css = read(path.join(args.page, 'replay.css'));
const app = checkScript(read(path.join(args.page, 'replay.js')), 'replay.js');
if (/<\/style/i.test(css)) fail('replay.css contains "</style", which would end its style element');

const markers = {
  '<style>/*@KELP_STYLE@*/</style>': `<style>\n${css}\n</style>`,
  '<script>/*@KELP_THREE@*/</script>': `<script>\n${three}\n</script>`,
  '<script>/*@KELP_APP@*/</script>': `<script>\n${app}\n</script>`,
};
let out = page;
for (const [marker, text] of Object.entries(markers)) {
  const parts = out.split(marker);
  if (parts.length !== 2) fail(`${path.join(args.page, 'replay.html')} must contain ${marker} exactly once`);
  out = parts[0] + text + parts[1]; // no String.replace: three.js holds `$&` patterns
}
if (out.split('<script>/*@KELP_DATA@*/</script>').length !== 2)
  fail(`${path.join(args.page, 'replay.html')} must contain <script>/*@KELP_DATA@*/</script> exactly once`);

fs.mkdirSync(path.dirname(args.out), { recursive: true });
const tmp = `${args.out}.tmp`;
fs.writeFileSync(tmp, out);
fs.renameSync(tmp, args.out);
