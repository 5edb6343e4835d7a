// `keyanim view`: the page it writes embeds the clip (and original) byte for byte; its outputs
// follow the CLI's rules (no clobbering without -f, never an input); it opens the page with
// xdg-open only when there is a display; a missing page or bad input fails clearly.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { keyanimCli, viewerPage, sourceDir, vectorsDir, exists } from './paths.mjs';

const skip = !exists(keyanimCli) ? `no keyanim CLI at ${keyanimCli}` : !exists(viewerPage) ? `no built viewer page at ${viewerPage}` : false;
const walk = path.join(sourceDir, 'data/cmu_02_01_walk.bvh'), hop = path.join(sourceDir, 'data/cmu_131_03_hop.bvh');

function run(args, env = {}) {
  const r = spawnSync(keyanimCli, args, { encoding: 'utf8', env: { ...process.env, DISPLAY: '', WAYLAND_DISPLAY: '', KEYANIM_VIEWER_PAGE: viewerPage, ...env } });
  return { code: r.status, out: r.stdout, err: r.stderr };
}
const embeddedBytes = (html, id) => {
  const m = new RegExp(`<script type="application/octet-stream" id="${id}" data-name="([^"]*)">([^<]*)</script>`).exec(html);
  return m && { name: m[1], bytes: Buffer.from(m[2], 'base64') };
};

test('keyanim view', { skip }, (t) => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-view-'));
  t.after(() => fs.rmSync(dir, { recursive: true, force: true }));
  const kanim = path.join(dir, 'walk.kanim'), hopKanim = path.join(dir, 'hop.kanim'), html = path.join(dir, 'walk.html');
  assert.equal(run(['encode', walk, '-o', kanim, '-q']).code, 0);
  assert.equal(run(['encode', hop, '-o', hopKanim, '-q']).code, 0);

  // The page: the template with the clip and the original embedded, nothing else changed.
  let r = run(['view', kanim, '--against', walk, '-o', html]);
  assert.equal(r.code, 0, r.err);
  assert.equal(r.out, `${html}\n`);
  const page = fs.readFileSync(html, 'utf8'), template = fs.readFileSync(viewerPage, 'utf8');
  const clip = embeddedBytes(page, 'keyanim-embedded-clip'), orig = embeddedBytes(page, 'keyanim-embedded-original');
  assert.deepEqual([clip.name, orig.name], ['walk.kanim', 'cmu_02_01_walk.bvh']);
  assert.ok(clip.bytes.equals(fs.readFileSync(kanim)) && orig.bytes.equals(fs.readFileSync(walk)));
  const [head, tail] = template.split('<!-- keyanim:embed -->');
  assert.ok(page.startsWith(head) && page.endsWith(tail));

  // Outputs: never clobbered without -f, never an input; the default is a new temporary file.
  r = run(['view', kanim, '-o', html]);
  assert.equal(r.code, 4, 'an existing output is not overwritten without -f');
  assert.equal(run(['view', kanim, '-o', html, '-f']).code, 0);
  assert.equal(run(['view', kanim, '--against', walk, '-o', walk, '-f']).code, 4, 'an input is never an output (exit 4, like every command)');
  r = run(['view', kanim]);
  assert.equal(r.code, 0, r.err);
  const temp = r.out.trim();
  assert.ok(path.basename(temp).startsWith('keyanim-view-walk-') && temp.endsWith('.html') && embeddedBytes(fs.readFileSync(temp, 'utf8'), 'keyanim-embedded-clip'));
  fs.rmSync(temp);

  // Bad inputs: a damaged clip (exit 2, section and offset), an original of another skeleton.
  const damaged = path.join(dir, 'damaged.kanim');
  fs.writeFileSync(damaged, fs.readFileSync(path.join(vectorsDir, 'v3_rules.kanim')).subarray(0, 100));
  r = run(['view', damaged, '-o', path.join(dir, 'd.html')]);
  assert.equal(r.code, 2);
  assert.match(r.err, /offset \d+ .*truncated/);
  r = run(['view', hopKanim, '--against', walk, '-o', path.join(dir, 'm.html')]);
  assert.equal(r.code, 2);
  assert.match(r.err, /hierarchy or channels differ/);

  // No page: exit 3, naming where it looked.
  r = run(['view', kanim, '-o', path.join(dir, 'n.html')], { KEYANIM_VIEWER_PAGE: path.join(dir, 'nowhere.html') });
  assert.equal(r.code, 3);
  assert.match(r.err, /viewer page is not installed.*looked for .*nowhere\.html; set KEYANIM_VIEWER_PAGE/);

  // xdg-open: called with the page when DISPLAY is set, not with --no-open or without a display.
  const bin = path.join(dir, 'bin'), log = path.join(dir, 'xdg-open.log');
  fs.mkdirSync(bin);
  fs.writeFileSync(path.join(bin, 'xdg-open'), `#!/bin/sh\necho "$@" >> '${log}'\n`, { mode: 0o755 });
  const withFake = { PATH: `${bin}:${process.env.PATH}` };
  assert.equal(run(['view', kanim, '-o', path.join(dir, 'a.html')], { ...withFake, DISPLAY: ':0' }).code, 0);
  assert.equal(run(['view', kanim, '-o', path.join(dir, 'b.html'), '--no-open'], { ...withFake, DISPLAY: ':0' }).code, 0);
  assert.equal(run(['view', kanim, '-o', path.join(dir, 'c.html')], withFake).code, 0);
  assert.equal(fs.readFileSync(log, 'utf8'), `${path.join(dir, 'a.html')}\n`);
});
