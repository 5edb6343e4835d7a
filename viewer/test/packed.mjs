// The keyanim-three package as a user gets it: `npm pack` in packages/keyanim-three, then
// `npm install` of the tarball into a fresh folder, next to three and fzstd. Offline: with an
// empty npm cache and --offline, three and fzstd come from the viewer's node_modules (the
// versions `npm ci` installed), so the test needs no registry.
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
export const packageDir = path.resolve(here, '../packages/keyanim-three');
const viewerModules = path.resolve(here, '../node_modules');
export const npm = process.env.KEYANIM_NPM || 'npm';
const OFFLINE = ['--offline', '--no-audit', '--no-fund', '--ignore-scripts', '--loglevel=error'];

// Packs the package into dir; returns { tarball, files } (files: the paths inside the tarball).
export function pack(dir) {
  const out = execFileSync(npm, ['pack', '--json', '--pack-destination', dir, ...OFFLINE, '--cache', path.join(dir, 'npm-cache')],
    { cwd: packageDir, encoding: 'utf8' });
  const [info] = JSON.parse(out);
  return { tarball: path.join(dir, info.filename), files: info.files.map((f) => f.path).sort() };
}

// A fresh folder under dir with the tarball, three and fzstd installed; returns its path.
export function installFresh(dir, tarball) {
  const app = path.join(dir, 'app');
  fs.mkdirSync(app);
  fs.writeFileSync(path.join(app, 'package.json'), JSON.stringify({ name: 'app', private: true, type: 'module' }));
  execFileSync(npm, ['install', ...OFFLINE, '--cache', path.join(dir, 'npm-cache'), tarball,
    path.join(viewerModules, 'three'), path.join(viewerModules, 'fzstd')], { cwd: app, encoding: 'utf8' });
  return app;
}
