// Where the tests find the repository (spec/, data/), the keyanim CLI and the corpus. CTest sets
// the environment; run by hand from viewer/, the defaults find the checkout and ../shared.
import path from 'node:path';
import fs from 'node:fs';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
export const sourceDir = process.env.KEYANIM_SOURCE_DIR || path.resolve(here, '../..');
export const vectorsDir = path.join(sourceDir, 'spec/test-vectors');
export const corpusDir = process.env.KEYANIM_CORPUS || path.resolve(sourceDir, '../shared/corpus');
export const keyanimCli = process.env.KEYANIM_CLI || path.join(sourceDir, 'build/tools/keyanim');
export const viewerPage = process.env.KEYANIM_VIEWER_PAGE || path.resolve(here, '../dist/index.html');
export const exists = (p) => { try { fs.accessSync(p); return true; } catch { return false; } };

// Every .bvh below dir, sorted (the corpus keeps its clips in subfolders).
export function bvhFilesBelow(dir) {
  if (!exists(dir)) return [];
  return fs.readdirSync(dir, { recursive: true }).filter((f) => f.endsWith('.bvh')).sort().map((f) => path.join(dir, f));
}
