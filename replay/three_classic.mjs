// Turns three.js's ES module build into ONE classic script that defines `window.THREE`, for
// replay.html: ES modules do not load from file:// (each import is a fetch that Chromium and
// Firefox refuse for file: URLs), and three ≥ r160 ships no UMD build. Since r178 (checked on
// 0.187.0), build/three.cjs is only `module.exports = require('./three.module.js')`, so it cannot
// be inlined either.
//
// three.module.js is `import {…} from './three.core.js'; export {…} from './three.core.js';`, its
// own code, and one `export {…};`. three.core.js is self-contained code ending in one
// `export {…};`. Each becomes a function scope (strict, as modules are) returning its exports;
// nothing else in the code changes. The script refuses (exit 1) any other shape, so an update of
// `three` that changes the build's layout fails the build instead of producing a broken page.
//
// usage: node three_classic.mjs <three/build directory> <output .js>
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';

function fail(msg) {
  console.error(`three_classic: ${msg}`);
  process.exit(1);
}

if (process.argv.length !== 4) fail('usage: node three_classic.mjs <three/build directory> <output .js>');
const [dir, out] = process.argv.slice(2);
const core = readFileSync(join(dir, 'three.core.js'), 'utf8');
const mod = readFileSync(join(dir, 'three.module.js'), 'utf8');

// A top-level import/export statement: at the start of a line (the builds are not minified).
const statement = /^(import|export)\s*\{([^}]*)\}\s*(?:from\s*'([^']*)')?\s*;[ \t]*$/gm;

// Parses `a, b as c` into [[exported-or-imported name, local name], …].
function names(list) {
  return list
    .split(',')
    .map((s) => s.trim())
    .filter((s) => s.length > 0)
    .map((s) => {
      const m = /^([A-Za-z_$][\w$]*)(?:\s+as\s+([A-Za-z_$][\w$]*))?$/.exec(s);
      if (!m) fail(`unexpected name in an import/export list: '${s}'`);
      return [m[1], m[2] ?? m[1]];
    });
}

// Replaces every import/export statement of `src`; returns the code and what it exports.
function convert(src, file) {
  const exportsOf = []; // [exported name, expression]
  const code = src.replace(statement, (_, kind, list, from) => {
    if (kind === 'import') {
      if (from !== './three.core.js') fail(`${file}: import from '${from}'`);
      // import { a as b } → local b is the core's a
      return `const { ${names(list).map(([a, b]) => `${a}: ${b}`).join(', ')} } = __core;`;
    }
    if (from !== undefined) {
      if (from !== './three.core.js') fail(`${file}: export from '${from}'`);
      for (const [a, b] of names(list)) exportsOf.push([b, `__core.${a}`]);
    } else {
      // export { a as b } → exported b is local a
      for (const [a, b] of names(list)) exportsOf.push([b, a]);
    }
    return '';
  });
  // Anything module-only that is left would break (or silently change) a classic script.
  if (/^\s*(import|export)\b/m.test(code) || /\bimport\s*\(|\bimport\.meta\b/.test(code))
    fail(`${file}: an import/export this script does not handle`);
  if (exportsOf.length === 0) fail(`${file}: no exports found`);
  return { code, exportsOf };
}

const c = convert(core, 'three.core.js');
if (/\b__core\b/.test(core)) fail('three.core.js uses the name __core');
const m = convert(mod, 'three.module.js');
const object = (list) => `{ ${list.map(([name, expr]) => `${name}: ${expr}`).join(', ')} }`;

const result = `/* three.js ${JSON.parse(readFileSync(join(dir, '..', 'package.json'), 'utf8')).version}
 * (MIT licence, Copyright three.js authors; https://threejs.org), its ES module build
 * (build/three.core.js and build/three.module.js) made into one classic script that defines
 * window.THREE by kelp's replay/three_classic.mjs. */
window.THREE = (function () {
const __core = (function () {
'use strict';
${c.code}
return ${object(c.exportsOf)};
})();
return Object.freeze((function () {
'use strict';
${m.code}
return ${object(m.exportsOf)};
})());
})();
`;
// The result is inlined in a <script> element: it must not close it.
if (/<\/script/i.test(result)) fail("the result contains '</script'");
writeFileSync(out, result);
