// Builds the viewer: src/main.js and what it imports (three.js and fzstd from node_modules)
// bundled by esbuild into one script, inlined into src/index.html, written as OUTDIR/index.html
// (default dist/). The page needs no network and works from file://.
// Usage: node build.mjs [OUTDIR]
import { build } from 'esbuild';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const outDir = path.resolve(process.argv[2] ?? path.join(here, 'dist'));
const SCRIPT = '<!-- keyanim:script -->', EMBED = '<!-- keyanim:embed -->';

const result = await build({
  entryPoints: [path.join(here, 'src/main.js')],
  bundle: true, minify: true, format: 'iife', target: 'es2020', write: false, legalComments: 'none',
  logLevel: 'warning',
});
// "</script" cannot appear inside an inline script; "<\/script" means the same in JS text.
const js = result.outputFiles[0].text.replaceAll('</script', '<\\/script');
if (js.includes(EMBED)) throw new Error('the bundle contains the embed marker');

const licenses = ['three', 'fzstd'].map((p) => `${p}:\n${fs.readFileSync(path.join(here, 'node_modules', p, 'LICENSE'), 'utf8').trim()}`);
const template = fs.readFileSync(path.join(here, 'src/index.html'), 'utf8');
if (template.split(SCRIPT).length !== 2 || template.split(EMBED).length !== 2) throw new Error('src/index.html needs each marker exactly once');
const page = template.replace(SCRIPT, () => `<script>${js}</script>\n<!-- Bundled libraries:\n${licenses.join('\n\n')}\n-->`);

fs.mkdirSync(outDir, { recursive: true });
const tmp = path.join(outDir, `.index.html.${process.pid}`);
fs.writeFileSync(tmp, page);
fs.renameSync(tmp, path.join(outDir, 'index.html'));
console.log(`keyanim viewer: ${path.join(outDir, 'index.html')} (${page.length} bytes)`);
