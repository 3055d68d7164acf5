// Bundles src/viewer.js with three.js into one minified script: node build.mjs OUTFILE
// (experiments/CMakeLists.txt runs it; `bodypoint view` inlines the result into every page).
import { buildSync } from 'esbuild';
import { readFileSync } from 'node:fs';

const outfile = process.argv[2] || 'dist/viewer.js';
buildSync({
  entryPoints: [new URL('./src/viewer.js', import.meta.url).pathname],
  bundle: true, minify: true, format: 'iife', target: 'es2020', legalComments: 'eof', logLevel: 'warning', outfile,
});
// The script is inlined into <script>...</script>: it must not contain the closing tag.
if (/<\/script/i.test(readFileSync(outfile, 'utf8'))) {
  console.error(`build.mjs: ${outfile} contains "</script", which would end the page's script early`);
  process.exit(1);
}
