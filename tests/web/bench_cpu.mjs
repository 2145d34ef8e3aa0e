// CPU a frame of the page (all Chromium processes, from /proc) for CesiumMan at 960x600,
// textured, for one or more `make web` outputs in turn (A/B comparisons on a loaded machine:
// the rounds alternate, and the least CPU of each build is its best estimate). Not a test.
//   node tests/web/bench_cpu.mjs CESIUMMAN.glb ROUNDS WEB_DIR [WEB_DIR...]
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import puppeteer from 'puppeteer-core';

const [glbPath, roundsArg, ...dirs] = process.argv.slice(2);
if (!glbPath || !dirs.length) { console.error('usage: node bench_cpu.mjs CESIUMMAN.glb ROUNDS WEB_DIR [WEB_DIR...]'); process.exit(2); }
const glb = fs.readFileSync(glbPath).toString('base64');
function cpuOf(rootPid) { // CPU seconds of a process tree (Linux /proc)
  const procs = new Map();
  for (const d of fs.readdirSync('/proc')) {
    if (!/^\d+$/.test(d)) continue;
    let st;
    try { st = fs.readFileSync(`/proc/${d}/stat`, 'utf8'); } catch { continue; }
    const f = st.slice(st.lastIndexOf(')') + 2).split(' ');
    procs.set(Number(d), { ppid: Number(f[1]), cpu: (Number(f[11]) + Number(f[12])) / 100 });
  }
  let total = 0;
  for (const [pid, v] of procs) {
    for (let p = pid, n = 0; p > 1 && n < 64; p = (procs.get(p) || { ppid: 0 }).ppid, n++) if (p === rootPid) { total += v.cpu; break; }
  }
  return total;
}
async function measure(dir) {
  const root = path.resolve(dir);
  const server = http.createServer((req, res) => {
    const file = path.join(root, new URL(req.url, 'http://x').pathname.replace(/^\/+/, '') || 'index.html');
    if (!fs.existsSync(file)) { res.writeHead(404); res.end(); return; }
    res.writeHead(200, { 'Content-Type': file.endsWith('.wasm') ? 'application/wasm' : file.endsWith('.js') ? 'text/javascript' : 'text/html' });
    fs.createReadStream(file).pipe(res);
  });
  await new Promise((r) => server.listen(0, '127.0.0.1', r));
  const browser = await puppeteer.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run', '--disable-extensions'] });
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1000, height: 760 });
    await page.goto(`http://127.0.0.1:${server.address().port}/index.html?paused=1`, { waitUntil: 'load' });
    await page.evaluate(() => window.animkit.ready);
    await page.evaluate(async (b64) => {
      const a = window.animkit;
      if (!(await a.openBytes('CesiumMan.glb', Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))))) throw new Error(a.error());
      for (let k = 0; k < 20; k++) a.frame(1 / 30);
    }, glb);
    const pid = browser.process().pid;
    const c0 = cpuOf(pid);
    await page.evaluate(() => { for (let k = 0; k < 90; k++) window.animkit.frame(1 / 30); });
    const c1 = cpuOf(pid);
    await page.evaluate(() => { for (let k = 0; k < 90; k++) window.animkit.frame(1 / 30, false); });
    const c2 = cpuOf(pid);
    return { page: (1000 * (c1 - c0)) / 90, module: (1000 * (c2 - c1)) / 90 };
  } finally {
    await browser.close();
    server.close();
  }
}
const best = new Map();
for (let r = 0; r < Number(roundsArg || 3); r++)
  for (const d of dirs) {
    const m = await measure(d);
    console.log(`${d}: page ${m.page.toFixed(2)} ms CPU a frame, module ${m.module.toFixed(2)} ms`);
    const b = best.get(d) || { page: Infinity, module: Infinity };
    best.set(d, { page: Math.min(b.page, m.page), module: Math.min(b.module, m.module) });
  }
for (const [d, b] of best) console.log(`least of ${d}: page ${b.page.toFixed(2)} ms (${(1000 / b.page).toFixed(1)} fps), module ${b.module.toFixed(2)} ms`);
