// Where the page's frame time goes: V8's sampling profiler (DevTools protocol) over CesiumMan
// at 960x600, textured, in Debian's headless Chromium. Not a test; docs/web.md uses its output.
//   AK_WEB_STRIP=0 scripts/build-web.sh build/web-prof     (function names kept)
//   node tests/web/profile.mjs build/web-prof CESIUMMAN.glb [FRAMES]
// Prints the functions with the most self time (% of the samples inside akw_frame's calls).
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import puppeteer from 'puppeteer-core';

const [webArg, glbPath, framesArg] = process.argv.slice(2);
if (!webArg || !glbPath) { console.error('usage: node profile.mjs WEB_DIR CESIUMMAN.glb [FRAMES]'); process.exit(2); }
const webDir = path.resolve(webArg), frames = Number(framesArg || 60);
const types = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm' };
const server = http.createServer((req, res) => {
  const rel = decodeURIComponent(new URL(req.url, 'http://x').pathname).replace(/^\/+/, '') || 'index.html';
  const file = path.join(webDir, rel);
  if (!file.startsWith(webDir + path.sep) || !fs.existsSync(file)) { res.writeHead(404); res.end(); return; }
  res.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream' });
  fs.createReadStream(file).pipe(res);
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const browser = await puppeteer.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run', '--disable-extensions'] });
try {
  const page = await browser.newPage();
  await page.goto(`http://127.0.0.1:${server.address().port}/index.html?paused=1`, { waitUntil: 'load' });
  await page.evaluate(() => window.animkit.ready);
  const err = await page.evaluate(async (b64) => {
    const a = window.animkit;
    if (!(await a.openBytes('CesiumMan.glb', Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))))) return a.error();
    for (let k = 0; k < 10; k++) a.frame(1 / 30);
    return '';
  }, fs.readFileSync(glbPath).toString('base64'));
  if (err) throw new Error(err);
  const cdp = await page.target().createCDPSession();
  await cdp.send('Profiler.enable');
  await cdp.send('Profiler.setSamplingInterval', { interval: 200 });
  await cdp.send('Profiler.start');
  await page.evaluate((n) => { for (let k = 0; k < n; k++) window.animkit.frame(1 / 30, false); }, frames);
  const { profile } = await cdp.send('Profiler.stop');
  const self = new Map(), byId = new Map(profile.nodes.map((n) => [n.id, n]));
  const counts = new Map();
  for (const id of profile.samples) counts.set(id, (counts.get(id) || 0) + 1);
  let total = 0;
  for (const [id, c] of counts) {
    const name = byId.get(id).callFrame.functionName || '(anonymous)';
    if (name === '(idle)' || name === '(program)' || name === '(garbage collector)') continue;
    self.set(name, (self.get(name) || 0) + c);
    total += c;
  }
  const rows = [...self].sort((p, q) => q[1] - p[1]).slice(0, 25);
  for (const [name, c] of rows) console.log(`${((100 * c) / total).toFixed(1).padStart(5)}%  ${name}`);
  console.log(`${total} samples of 0.2 ms over ${frames} frames: ${((total * 0.2) / frames).toFixed(1)} ms a frame`);
} finally {
  await browser.close();
  server.close();
}
