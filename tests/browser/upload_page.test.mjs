// Browser test of the upload page: starts soupuv-server (real CLI as worker)
// on 127.0.0.1 with a free port, drives Debian's chromium through
// playwright-core, uploads a sample with the default method (field) at a coarse
// proxy resolution and debug outputs on, and checks what a user sees: stage
// progress while it runs, the viewer drew a textured model, toggles for soup,
// proxy and field lines (turning the proxy on changes the picture), the UV
// layout image, the summary of the diagnostics (figures judged against the
// targets; the raw rows behind a closed disclosure), the finished stages in
// pipeline order, the checker toggle (changes the picture) and the convergence
// plot. With --folder DIR it then uploads DIR's files at once (a .gltf with
// its .bin and images) and checks the texture was re-baked. Saves a screenshot.
//
//   node upload_page.test.mjs --server BIN --worker BIN --sample FILE --out DIR
// Prints "1 passed, 0 failed" or "0 passed, 1 failed" and exits accordingly.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { chromium } from 'playwright-core';

const args = Object.fromEntries(process.argv.slice(2).reduce((acc, a, i, all) => {
  if (a.startsWith('--')) acc.push([a.slice(2), all[i + 1]]);
  return acc;
}, []));
for (const k of ['server', 'worker', 'sample', 'out']) {
  if (!args[k]) { console.error(`missing --${k}`); process.exit(2); }
}
if (!fs.existsSync(args.sample)) {
  console.log(`SKIPPED: the sample ${args.sample} is absent (no ../shared/data)`);
  process.exit(77);
}
fs.mkdirSync(args.out, { recursive: true });
const dataDir = fs.mkdtempSync(path.join(args.out, 'data-'));
const profile = fs.mkdtempSync(path.join(args.out, 'profile-'));

function startServer() {
  return new Promise((resolve, reject) => {
    const proc = spawn(args.server, ['--host', '127.0.0.1', '--port', '0', '--data-dir', dataDir,
      '--worker-bin', args.worker, '--workers', '1'], { stdio: ['ignore', 'ignore', 'pipe'] });
    let log = '';
    const timer = setTimeout(() => reject(new Error(`server did not start:\n${log}`)), 30000);
    proc.stderr.on('data', (d) => {
      log += d;
      const m = log.match(/"msg":"listening","port":(\d+)/);
      if (m) { clearTimeout(timer); resolve({ proc, port: Number(m[1]), log: () => log }); }
    });
    proc.on('exit', (code) => reject(new Error(`server exited ${code}:\n${log}`)));
  });
}

let server, browser, failed = null;
try {
  server = await startServer();
  // A fresh profile directory (playwright passes it as --user-data-dir).
  browser = await chromium.launchPersistentContext(profile, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    viewport: { width: 1280, height: 900 },
    args: ['--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update',
      '--disable-sync', '--no-first-run', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  const page = browser.pages()[0] || await browser.newPage();
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));
  await page.goto(`http://127.0.0.1:${server.port}/`);
  await page.waitForSelector('#params label');  // the form came from /v1/params
  const method = await page.$eval('#params [name="method"]', (e) => e.value);
  if (method !== 'field') throw new Error(`the form's default method is ${method}, not field`);
  await page.fill('#params [name="resolution"]', '16');  // coarse: the test must stay fast
  await page.check('#params [name="debug_outputs"]');
  await page.setInputFiles('#file-input', args.sample);
  await page.click('#submit-button');
  await page.waitForFunction(() => ['succeeded', 'failed', 'canceled'].includes(
    document.getElementById('job-state').dataset.state), null, { timeout: 90000 });
  const jobState = await page.$eval('#job-state', (e) => e.dataset.state);
  if (jobState !== 'succeeded') throw new Error(`job ended ${jobState}: ${await page.$eval('#job-error', (e) => e.textContent)}`);
  await page.waitForFunction(() => window.__soupuvViewerReady === true && window.__soupuvResultShown === true,
    null, { timeout: 30000 });
  // Read the WebGL canvas back through a 2D canvas and count non-background pixels.
  const drawn = await page.evaluate(() => {
    const src = document.getElementById('viewer');
    const c = document.createElement('canvas');
    c.width = src.width; c.height = src.height;
    const g = c.getContext('2d');
    g.drawImage(src, 0, 0);
    const px = g.getImageData(0, 0, c.width, c.height).data;
    const bg = [0x20, 0x26, 0x2e];
    let other = 0, colors = new Set();
    for (let i = 0; i < px.length; i += 4) {
      const d = Math.abs(px[i] - bg[0]) + Math.abs(px[i + 1] - bg[1]) + Math.abs(px[i + 2] - bg[2]);
      if (d > 24) { other++; colors.add((px[i] >> 4) << 8 | (px[i + 1] >> 4) << 4 | (px[i + 2] >> 4)); }
    }
    return { fraction: other / (px.length / 4), colors: colors.size, width: c.width, height: c.height };
  });
  const rows = await page.$$eval('#diagnostics tbody tr', (r) => r.length);
  const layers = await page.$$eval('#layers label', (ls) => ls.map((l) => l.textContent.trim()));
  // Turning the proxy layer on must change the picture.
  const checksum = () => page.evaluate(() => {
    const src = document.getElementById('viewer');
    const c = document.createElement('canvas');
    c.width = src.width; c.height = src.height;
    const g = c.getContext('2d');
    g.drawImage(src, 0, 0);
    const px = g.getImageData(0, 0, c.width, c.height).data;
    let h = 0;
    for (let i = 0; i < px.length; i += 4) h = (h * 31 + px[i] + 7 * px[i + 1] + 13 * px[i + 2]) >>> 0;
    return h;
  });
  const before = await checksum();
  const proxyToggle = page.locator('#layers label', { hasText: 'proxy' }).locator('input');
  let proxyChanged = false;
  if (await proxyToggle.count() === 1) {
    await proxyToggle.check();
    proxyChanged = (await checksum()) !== before;
    await proxyToggle.uncheck();
  }
  const uvWidth = await page.$eval('#uv-layout', (img) => (img.closest('figure').hidden ? 0 : img.naturalWidth));
  const plotPoints = await page.evaluate(() => (document.getElementById('plot-figure').hidden ? 0 : window.__soupuvPlotPoints || 0));
  const stagesSeen = await page.evaluate(() => [...new Set(window.__soupuvStagesSeen || [])]);
  const stageRows = await page.$$eval('#stages li', (l) => l.length);
  const stageNames = await page.$$eval('#stages li', (l) => l.map((e) => e.textContent.split(':')[0]));
  const summary = await page.$$eval('#summary tbody tr', (r) => r.map((e) => [e.cells[0].textContent, e.className]));
  const rawOpen = await page.$eval('#raw-diagnostics', (d) => d.open);
  const downloadHref = await page.$eval('#diagnostics-download', (a) => a.href);
  const checkerToggle = page.locator('#layers label', { hasText: 'checker' }).locator('input');
  const beforeChecker = await checksum();
  await checkerToggle.check();
  const checkerChanged = (await checksum()) !== beforeChecker;
  await checkerToggle.uncheck();
  await page.screenshot({ path: path.join(args.out, 'upload-page.png'), fullPage: true });
  console.log(JSON.stringify({ drawn, diagnostics_rows: rows, layers, proxy_changed_picture: proxyChanged,
    uv_layout_width: uvWidth, convergence_points: plotPoints, stages_seen_running: stagesSeen,
    stage_rows: stageRows, stage_names: stageNames, summary, raw_open: rawOpen, checker_changed_picture: checkerChanged,
    console_errors: consoleErrors }));
  if (drawn.fraction < 0.02) throw new Error(`viewer drew almost nothing (${(drawn.fraction * 100).toFixed(2)}% non-background)`);
  if (drawn.colors < 8) throw new Error(`viewer shows ${drawn.colors} colour classes: no texture?`);
  if (rows < 5) throw new Error(`diagnostics table has ${rows} rows`);
  for (const want of ['textured soup', 'proxy', 'field lines'])
    if (!layers.includes(want)) throw new Error(`no '${want}' toggle (layers: ${layers.join(', ')})`);
  if (!proxyChanged) throw new Error('turning the proxy layer on did not change the picture');
  if (uvWidth < 64) throw new Error(`UV layout image not shown (width ${uvWidth})`);
  if (plotPoints < 1) throw new Error('no convergence plot');
  if (stagesSeen.length < 2) throw new Error(`stage progress not shown while running (saw: ${stagesSeen.join(', ')})`);
  if (stageRows < 4) throw new Error(`finished-stage list has ${stageRows} entries`);
  // Pipeline order: load first, the proxy before the atlas, charge before trace, write last.
  const at = (p) => stageNames.findIndex((n) => n === p || n.startsWith(`${p}_`));
  for (const [a, b] of [['load', 'write'], ['proxy', 'atlas'], ['charge', 'trace'], ['trace', 'transfer'], ['uv_solve', 'write']])
    if (at(a) >= 0 && at(b) >= 0 && at(a) > at(b)) throw new Error(`stage ${a} listed after ${b}: ${stageNames.join(', ')}`);
  if (at('load') !== 0) throw new Error(`stages do not start with load: ${stageNames.join(', ')}`);
  const judged = summary.filter(([, c]) => ['good', 'near', 'bad'].includes(c)).map(([l]) => l);
  for (const want of ['Continuity', 'Overlap', 'Utilisation', 'Stretch (L2)', 'Flipped triangles'])
    if (!judged.includes(want)) throw new Error(`summary lacks a judged '${want}' (rows: ${JSON.stringify(summary)})`);
  if (!summary.some(([l]) => l === 'Time')) throw new Error('summary has no time');
  if (rawOpen) throw new Error('the raw diagnostics are open by default');
  if (!downloadHref.startsWith('blob:')) throw new Error('no diagnostics download link');
  if (!checkerChanged) throw new Error('the checker toggle did not change the picture');
  if (consoleErrors.length) throw new Error(`page errors: ${consoleErrors.join(' | ')}`);

  if (args.folder) {
    // A .gltf with its files picked at once: the page sends them as "files"
    // parts, the server maps it, the texture is the re-baked base colour.
    const files = fs.readdirSync(args.folder).map((f) => path.join(args.folder, f));
    await page.selectOption('#params [name="method"]', 'box');
    await page.setInputFiles('#file-input', files);
    await page.evaluate(() => { window.__soupuvViewerReady = false; window.__soupuvResultShown = false; });
    await page.click('#submit-button');
    await page.waitForFunction(() => window.__soupuvResultShown === true ||
      ['failed', 'canceled'].includes(document.getElementById('job-state').dataset.state), null, { timeout: 90000 });
    const texture = await page.$$eval('#summary tbody tr', (r) => r.map((e) => [e.cells[0].textContent, e.cells[1].textContent]));
    const row = texture.find(([l]) => l === 'Texture');
    console.log(JSON.stringify({ folder_upload: texture }));
    if (!row || !row[1].startsWith('re-baked')) throw new Error(`folder upload: texture ${JSON.stringify(row)}, expected re-baked`);
  }
} catch (e) {
  failed = e;
} finally {
  if (browser) await browser.close();
  if (server) server.proc.kill('SIGTERM');
  fs.rmSync(profile, { recursive: true, force: true });
  fs.rmSync(dataDir, { recursive: true, force: true });
}
if (failed) {
  console.error(`FAIL: ${failed.message}`);
  console.log('0 passed, 1 failed');
  process.exit(1);
}
console.log(`screenshot: ${path.join(args.out, 'upload-page.png')}`);
console.log('1 passed, 0 failed');
