// Browser tests of the WebAssembly page (docs/web.md): Debian's Chromium, headless, driven by
// puppeteer-core. Usage:
//   node tests/web/run.mjs WEB_DIR ANIMKIT_CLI OUT_DIR [CESIUMMAN.glb]
// WEB_DIR holds `make web`'s output (index.html, animkit.wasm); ANIMKIT_CLI is the native
// command (the cloth reference); OUT_DIR receives the screenshots and results.json. Exit 0 pass,
// 1 fail, 77 skip (no Chromium, no puppeteer-core).
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const [webArg, cli, outDir, cesium] = process.argv.slice(2);
const webDir = webArg && path.resolve(webArg);
if (!webArg || !cli || !outDir) {
  console.error('usage: node run.mjs WEB_DIR ANIMKIT_CLI OUT_DIR [CESIUMMAN.glb]');
  process.exit(2);
}
const chromium = process.env.CHROMIUM || ['/usr/bin/chromium', '/usr/bin/chromium-browser'].find((p) => fs.existsSync(p));
if (!chromium) {
  console.log('SKIP: no Chromium (Debian: apt-get install chromium; or set CHROMIUM)');
  process.exit(77);
}
let puppeteer;
try {
  puppeteer = (await import('puppeteer-core')).default;
} catch {
  console.log('SKIP: puppeteer-core is not installed (cd tests/web && npm ci)');
  process.exit(77);
}
fs.mkdirSync(outDir, { recursive: true });

// ---- a static server on 127.0.0.1 for WEB_DIR ----
const types = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm' };
const server = http.createServer((req, res) => {
  const rel = decodeURIComponent(new URL(req.url, 'http://x').pathname).replace(/^\/+/, '') || 'index.html';
  const file = path.join(webDir, rel);
  if (!file.startsWith(webDir + path.sep) || !fs.existsSync(file)) { res.writeHead(404); res.end(); return; }
  res.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream' });
  fs.createReadStream(file).pipe(res);
});
await new Promise((r) => server.listen(0, '127.0.0.1', r));
const origin = `http://127.0.0.1:${server.address().port}`;

// CPU seconds (user + system) of a process and its descendants, from /proc (Linux).
function chromiumCpuSeconds(rootPid) {
  const tick = 100; // USER_HZ on Linux
  const kids = new Map();
  let total = 0;
  for (const d of fs.readdirSync('/proc')) {
    if (!/^\d+$/.test(d)) continue;
    let st;
    try { st = fs.readFileSync(`/proc/${d}/stat`, 'utf8'); } catch { continue; }
    const f = st.slice(st.lastIndexOf(')') + 2).split(' ');
    kids.set(Number(d), { ppid: Number(f[1]), cpu: (Number(f[11]) + Number(f[12])) / tick });
  }
  const inTree = (pid) => { for (let p = pid, n = 0; p > 1 && n < 64; p = (kids.get(p) || { ppid: 0 }).ppid, n++) if (p === rootPid) return true; return false; };
  for (const [pid, v] of kids) if (inTree(pid)) total += v.cpu;
  return total;
}

let failures = 0;
const results = {};
function check(ok, what, detail) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}${detail ? ': ' + detail : ''}`);
  if (!ok) failures++;
}

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--no-first-run', '--disable-extensions'],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1000, height: 760 });
  const consoleErrors = [], offsite = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));
  await page.setRequestInterception(true);
  page.on('request', (req) => {
    if (req.url().startsWith(origin + '/') || req.url().startsWith('data:')) req.continue();
    else { offsite.push(req.url()); req.abort(); }
  });

  // ---- 1. the page loads, nothing from the network, no console errors ----
  await page.goto(`${origin}/index.html?paused=1`, { waitUntil: 'load' });
  const loaded = await page.evaluate(() => window.animkit && window.animkit.ready.then(() => true, (e) => String(e)));
  if (loaded !== true) throw new Error(`the page did not start: ${loaded}; console: ${consoleErrors.join(' | ')}`);
  const wasmBytes = await page.evaluate(() => window.animkit.wasmBytes);
  results.wasm_bytes = wasmBytes;
  check(wasmBytes > 0 && wasmBytes <= 1.5 * 1024 * 1024, 'animkit.wasm is at most 1.5 MB', `${wasmBytes} bytes`);
  const canvas = await page.$('#view');
  const shot = async (name) => { await canvas.screenshot({ path: path.join(outDir, name) }); };
  await page.evaluate(() => window.animkit.frame(0));
  await shot('01_humanoid.png');

  // ---- 2. drag an IK target with the mouse; the effector follows within 1e-3 ----
  const ik = await page.evaluate(() => {
    const a = window.animkit;
    a.open('builtin:humanoid', 960, 600);
    a.key(' '); // pause the walk: the target is dragged on a still pose
    a.frame(0);
    const j = a.jointFind('left_wrist');
    return { j, xy: a.jointScreen(j) };
  });
  check(ik.j >= 0 && ik.xy, 'builtin:humanoid has a left_wrist on screen', JSON.stringify(ik));
  const box = await canvas.boundingBox();
  const sx = box.width / 960, sy = box.height / 600; // canvas pixels -> page pixels
  const drags = [[18, -22], [-10, 14], [6, 8]];
  let x = box.x + ik.xy[0] * sx, y = box.y + ik.xy[1] * sy;
  const ikRows = [];
  for (const [dx, dy] of drags) {
    // press on the effector (the first press picks the joint, later ones grab its target marker)
    await page.mouse.move(x, y);
    await page.mouse.down();
    for (let k = 1; k <= 8; k++) await page.mouse.move(x + (dx * k) / 8, y + (dy * k) / 8);
    await page.mouse.up();
    x += dx; y += dy;
    const r = await page.evaluate(() => {
      const a = window.animkit;
      a.frame(0); // poses with IK towards the dragged target
      return { eff: a.ikEffector(), target: a.ikTarget(), pos: a.ikEffectorPosition() };
    });
    const d = r.pos ? Math.hypot(r.pos[0] - r.target[0], r.pos[1] - r.target[1], r.pos[2] - r.target[2]) : Infinity;
    ikRows.push({ ...r, distance: d });
    check(r.eff === ik.j && d <= 1e-3, `IK drag ${ikRows.length}: effector within 1e-3 of the target`,
          `effector joint ${r.eff}, distance ${d.toExponential(2)}, target ${r.target && r.target.map((v) => v.toFixed(3))}`);
  }
  const moved = ikRows.length && ikRows[0].target && (() => {
    const t0 = ikRows[0].target, t2 = ikRows[ikRows.length - 1].target;
    return Math.hypot(t0[0] - t2[0], t0[1] - t2[1], t0[2] - t2[2]);
  })();
  check(moved > 0.01, 'the drags moved the target', `${moved}`);
  results.ik = ikRows;
  await shot('02_ik_drag.png');

  // ---- 3. switching LBS / DQS / CoR changes pixels ----
  const methods = await page.evaluate(() => {
    const a = window.animkit;
    a.open('builtin:cylinder', 960, 600);
    a.key(' ');
    a.setTime(a.duration() * 0.5); // bent and twisted: where the methods differ most
    const grab = () => {
      a.frame(0);
      return Array.from(document.getElementById('view').getContext('2d').getImageData(0, 0, 960, 600).data);
    };
    const out = {};
    for (const [k, name] of [['1', 'lbs'], ['2', 'dqs'], ['3', 'cor']]) {
      a.key(k);
      out[name] = { method: a.method(), px: grab() };
    }
    const diff = (p, q) => { let n = 0; for (let i = 0; i < p.length; i += 4) if (p[i] !== q[i] || p[i + 1] !== q[i + 1] || p[i + 2] !== q[i + 2]) n++; return n; };
    return {
      methods: [out.lbs.method, out.dqs.method, out.cor.method],
      lbs_dqs: diff(out.lbs.px, out.dqs.px), dqs_cor: diff(out.dqs.px, out.cor.px), lbs_cor: diff(out.lbs.px, out.cor.px),
    };
  });
  results.methods = methods;
  check(methods.methods.join() === '0,1,2', 'keys 1, 2, 3 select LBS, DQS, CoR', methods.methods.join());
  for (const k of ['lbs_dqs', 'dqs_cor', 'lbs_cor'])
    check(methods[k] > 500, `switching ${k.replace('_', ' -> ')} changes pixels`, `${methods[k]} pixels differ`);
  await page.evaluate(() => { window.animkit.key('4'); window.animkit.frame(0); });
  await shot('03_methods_side_by_side.png');

  // ---- 4. cloth: the page's positions against the native command's ----
  const sceneText = fs.readFileSync(path.join(here, '..', '..', 'examples', 'cloth_flag.json'), 'utf8');
  const steps = 90;
  const native = path.join(outDir, 'cloth_native.json');
  execFileSync(cli, ['cloth', path.join(here, '..', '..', 'examples', 'cloth_flag.json'), '--steps', String(steps),
                     '--threads', '1', '--json', native], { stdio: ['ignore', 'ignore', 'inherit'] });
  const ref = JSON.parse(fs.readFileSync(native, 'utf8')).positions.flat().map(Math.fround);
  const got = await page.evaluate((t, s) => window.animkit.clothRun(t, s), sceneText, steps);
  let same = 0, maxDiff = 0;
  for (let i = 0; i < ref.length; i++) {
    if (Object.is(ref[i], got[i])) same++;
    maxDiff = Math.max(maxDiff, Math.abs(ref[i] - got[i]));
  }
  results.cloth = { steps, floats: ref.length, bit_identical: same, max_abs_diff: maxDiff };
  check(got.length === ref.length && ref.length > 0, 'cloth: as many positions as the native run', `${got.length} vs ${ref.length}`);
  check(maxDiff <= 1e-5, 'cloth: the page matches the native library', `${same}/${ref.length} floats bit-identical, max |diff| ${maxDiff}`);

  // ---- 5. the simulations run live ----
  results.sims = {};
  for (const what of ['particles:preset:fountain', 'cloth:preset:flag', 'boids:preset:flock', 'fluid:preset:dam', 'crowd:preset:circle', 'terrain']) {
    const r = await page.evaluate((w) => {
      const a = window.animkit;
      if (!a.open(w, 960, 600)) return { error: a.error() };
      const c = document.getElementById('view').getContext('2d');
      a.frame(0);
      const p0 = c.getImageData(0, 0, 960, 600).data.slice();
      const t0 = performance.now();
      let frames = 0;
      for (; frames < 20; frames++) if (a.frame(1 / 30) < 0) return { error: a.error() };
      const ms = (performance.now() - t0) / frames;
      const p1 = c.getImageData(0, 0, 960, 600).data;
      let n = 0;
      for (let i = 0; i < p1.length; i += 4) if (p0[i] !== p1[i] || p0[i + 1] !== p1[i + 1] || p0[i + 2] !== p1[i + 2]) n++;
      return { changed: n, ms };
    }, what);
    results.sims[what] = r;
    // the terrain stands still (its camera and erosion move only on keys): it must draw, not move
    const moves = what !== 'terrain';
    check(!r.error && (!moves || r.changed > 200), `${what} runs in the page`,
          r.error || `${r.changed} pixels changed over 20 frames, ${r.ms.toFixed(1)} ms a frame`);
    await shot(`05_${what.replace(/[:]/g, '_')}.png`);
  }

  // ---- 6. a .bvh through the page's file input (the drop path) ----
  const bvh = path.join(here, '..', 'fuzz', 'seeds', 'bvh_49_04_3frames.bvh');
  const input = await page.$('#file');
  await input.uploadFile(bvh);
  await page.waitForFunction(() => window.animkit.current === 'file:', { timeout: 10000 }).catch(() => {});
  const bvhState = await page.evaluate(() => { window.animkit.frame(0); return { current: window.animkit.current, joints: window.animkit.jointCount() }; });
  check(bvhState.current === 'file:' && bvhState.joints > 20, 'a .bvh given to the page\'s file input opens', JSON.stringify(bvhState));
  await page.evaluate(() => window.animkit.frame(0));
  await shot('06_bvh.png');

  // ---- 6b. a .glb dropped on the page (a real drop event carrying a File) ----
  const dropped = await page.evaluate(async () => {
    const b64 = (window.ANIMKIT_ASSETS || {})['RiggedFigure.glb'];
    if (!b64) return { skipped: true };
    window.animkit.open('builtin:cylinder');
    const dt = new DataTransfer();
    dt.items.add(new File([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], 'dropped.glb'));
    document.body.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
    for (let k = 0; k < 100 && window.animkit.current !== 'file:'; k++) await new Promise((r) => setTimeout(r, 50));
    window.animkit.frame(0);
    return { current: window.animkit.current, joints: window.animkit.jointCount() };
  });
  if (dropped.skipped) console.log('info no bundled RiggedFigure.glb: the drop check is skipped');
  else check(dropped.current === 'file:' && dropped.joints >= 19, 'a .glb dropped on the page opens (RiggedFigure: a skin of 19 joints among its nodes)', JSON.stringify(dropped));
  if (!dropped.skipped) await shot('06_dropped_glb.png');

  // ---- 7. CesiumMan textured: the browser decodes its JPEG, the library samples it ----
  // References from the native build: the texture as libjpeg decoded it (`animkit export` writes
  // it as a PNG beside an OBJ, rows flipped for OBJ's v axis) and the native viewer's frame 1
  // (`animkit view --headless --script`: one step of 1/30 s, then a screenshot). The page's
  // texture must hash the same, and its frame must match the native frame pixel for pixel
  // within a small mean difference (the HUD's first line differs: "30 fps (fixed step)" natively,
  // the measured rate in the page; those rows are left out).
  if (cesium && fs.existsSync(cesium)) {
    const exp = path.join(outDir, 'cesium_native.obj');
    execFileSync(cli, ['export', cesium, '-o', exp], { stdio: ['ignore', 'ignore', 'inherit'] });
    const texPng = fs.readFileSync(path.join(outDir, 'cesium_native_0.png')).toString('base64');
    const script = path.join(outDir, 'cesium_native_script.txt');
    fs.writeFileSync(script, 'wait 1\nscreenshot 07_cesiumman_native.png\nquit\n');
    execFileSync(cli, ['view', cesium, '--headless', '--size', '960x600', '--threads', '1', '--script', script,
                       '--shot-dir', outDir], { stdio: ['ignore', 'ignore', 'inherit'] });
    const framePng = fs.readFileSync(path.join(outDir, '07_cesiumman_native.png')).toString('base64');
    const glb = fs.readFileSync(cesium).toString('base64');
    const tex = await page.evaluate(async (data, texB64, frameB64) => {
      const a = window.animkit;
      const bytes = Uint8Array.from(atob(data), (c) => c.charCodeAt(0));
      const pngPixels = async (b64) => { // PNG decoding is lossless: these are the native bytes
        const bmp = await createImageBitmap(new Blob([Uint8Array.from(atob(b64), (c) => c.charCodeAt(0))], { type: 'image/png' }),
                                            { premultiplyAlpha: 'none', colorSpaceConversion: 'none' });
        const c = new OffscreenCanvas(bmp.width, bmp.height).getContext('2d');
        c.drawImage(bmp, 0, 0);
        return { w: bmp.width, h: bmp.height, px: c.getImageData(0, 0, bmp.width, bmp.height).data };
      };
      const grab = () => { a.frame(1 / 30); return document.getElementById('view').getContext('2d').getImageData(0, 0, 960, 600).data; };
      // untextured: the file without its decoded images (as the page drew it before)
      if (!(await a.openBytes('CesiumMan.glb', bytes, { textures: false }))) return { error: a.error() };
      const plain = grab();
      if (!(await a.openBytes('CesiumMan.glb', bytes))) return { error: a.error() };
      const given = a.imagesGiven, served = a.imagesServed(), info = a.textureInfo(0);
      const page = grab();
      // the native texture, rows flipped back, hashed as akw_texture_info hashes
      const nt = await pngPixels(texB64);
      let h = 2166136261;
      for (let y = nt.h - 1; y >= 0; y--)
        for (let i = y * nt.w * 4; i < (y + 1) * nt.w * 4; i++) h = Math.imul(h ^ nt.px[i], 16777619) >>> 0;
      const nf = await pngPixels(frameB64);
      // the head: above the joint drawn highest on screen (CesiumMan's neck-head joint)
      let top = null;
      for (let j = 0; j < a.jointCount(); j++) { const p = a.jointScreen(j); if (p && (!top || p[1] < top[1])) top = p; }
      let headDiff = 0, headN = 0, headColours = new Set();
      const x0 = Math.round(top[0]) - 20, y0 = Math.round(top[1]) - 60;
      for (let y = y0; y < y0 + 40; y++)
        for (let x = x0; x < x0 + 40; x++) {
          const i = 4 * (y * 960 + x);
          headN++;
          if (page[i] !== plain[i] || page[i + 1] !== plain[i + 1] || page[i + 2] !== plain[i + 2]) headDiff++;
          headColours.add((page[i] << 16) | (page[i + 1] << 8) | page[i + 2]);
        }
      // page against native, below the HUD's first line (rows 0..23)
      let sum = 0, n = 0, maxd = 0, same = 0, changedByTexture = 0;
      const bb = [960, 600, -1, -1]; // where pixels differ: x0, y0, x1, y1
      const bands = new Array(15).fill(0); // differing pixels in rows 0-39, 40-79, ...
      for (let y = 24; y < 600; y++)
        for (let x = 0; x < 960; x++) {
          const i = 4 * (y * 960 + x);
          let px = 0;
          for (let c = 0; c < 3; c++) { const d = Math.abs(page[i + c] - nf.px[i + c]); sum += d; px = Math.max(px, d); }
          n += 3;
          maxd = Math.max(maxd, px);
          if (px === 0) same++;
          else { bands[Math.floor(y / 40)]++; bb[0] = Math.min(bb[0], x); bb[1] = Math.min(bb[1], y); bb[2] = Math.max(bb[2], x); bb[3] = Math.max(bb[3], y); }
          if (page[i] !== plain[i] || page[i + 1] !== plain[i + 1] || page[i + 2] !== plain[i + 2]) changedByTexture++;
        }
      return { given, served, info, native_texture: { width: nt.w, height: nt.h, fnv1a: h }, native_frame: [nf.w, nf.h],
               head: { at: top, box: [x0, y0, 40, 40], differs_from_untextured: headDiff, pixels: headN, colours: headColours.size },
               frame_mean_abs_diff: sum / n, frame_max_diff: maxd, frame_identical_pixels: same, frame_pixels: n / 3, frame_diff_box: bb, frame_diff_rows_by_40: bands,
               pixels_changed_by_texture: changedByTexture };
    }, glb, texPng, framePng);
    // the same file dropped on the page (a real drop event carrying a File): textured too
    tex.dropped = await page.evaluate(async (data) => {
      const a = window.animkit;
      a.open('builtin:cylinder');
      const dt = new DataTransfer();
      dt.items.add(new File([Uint8Array.from(atob(data), (c) => c.charCodeAt(0))], 'CesiumMan.glb'));
      document.body.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
      for (let k = 0; k < 200 && a.current !== 'file:'; k++) await new Promise((r) => setTimeout(r, 50));
      return { current: a.current, served: a.imagesServed(), info: a.textureInfo(0) };
    }, glb);
    results.cesiumman_texture = tex;
    await shot('07_cesiumman_textured.png');
    if (tex.error) {
      check(false, 'CesiumMan loads in the page', tex.error);
    } else {
      check(tex.given === 1 && tex.served === 1, 'CesiumMan: the browser decoded its one texture image and the glTF reader took it',
            `${tex.given} given, ${tex.served} served`);
      check(tex.info && tex.info.width === tex.native_texture.width && tex.info.height === tex.native_texture.height &&
            tex.info.fnv1a === tex.native_texture.fnv1a,
            'CesiumMan: the texture\'s RGBA in the module is bit-identical to libjpeg\'s decode (native build)',
            `page ${JSON.stringify(tex.info)}, native ${JSON.stringify(tex.native_texture)}`);
      check(tex.dropped.current === 'file:' && tex.dropped.served === 1 && tex.dropped.info && tex.dropped.info.fnv1a === tex.native_texture.fnv1a,
            'CesiumMan dropped on the page opens textured, the same texture', JSON.stringify(tex.dropped));
      check(tex.head.differs_from_untextured > tex.head.pixels / 2 && tex.head.colours > 20,
            'CesiumMan\'s head is textured, not the flat untextured colour',
            `${tex.head.differs_from_untextured}/${tex.head.pixels} pixels of the box ${tex.head.box} (x, y, w, h) differ from the untextured frame, ${tex.head.colours} colours`);
      check(tex.pixels_changed_by_texture > 5000 && tex.frame_mean_abs_diff <= 0.5,
            'CesiumMan: the page\'s textured frame matches the native viewer\'s (mean |diff| <= 0.5 of 255)',
            `mean |diff| ${tex.frame_mean_abs_diff.toFixed(4)}, max ${tex.frame_max_diff}, ${tex.frame_identical_pixels}/${tex.frame_pixels} pixels identical (the others in x, y ${tex.frame_diff_box}); the texture changed ${tex.pixels_changed_by_texture} pixels`);
    }
  }

  // ---- 8. frame time: CesiumMan at 960x600, textured ----
  if (cesium && fs.existsSync(cesium)) {
    const b64 = fs.readFileSync(cesium).toString('base64');
    const loaded = await page.evaluate(async (data) => {
      const a = window.animkit;
      if (!(await a.openBytes('CesiumMan.glb', Uint8Array.from(atob(data), (c) => c.charCodeAt(0))))) return a.error();
      for (let k = 0; k < 10; k++) a.frame(1 / 30); // warm up
      return '';
    }, b64);
    // Wall time per frame inside the page, and the CPU time all of Chromium's processes spent
    // meanwhile (/proc): on a shared, loaded machine the wall time includes waiting for a core.
    const cpu0 = chromiumCpuSeconds(browser.process().pid);
    const perf = loaded ? { error: loaded } : await page.evaluate(() => {
      const a = window.animkit;
      const ms = [];
      const t0 = performance.now();
      for (let k = 0; k < 90; k++) ms.push(a.frame(1 / 30));
      const total = performance.now() - t0;
      ms.sort((p, q) => p - q);
      return { frames: 90, total_ms: total, median_ms: ms[45], mean_ms: total / 90, p90_ms: ms[81], stats: a.stats() };
    });
    if (!perf.error) {
      perf.cpu_ms_per_frame = (1000 * (chromiumCpuSeconds(browser.process().pid) - cpu0)) / perf.frames;
      // the module alone: the same frames drawn but not copied to the canvas
      const cpu1 = chromiumCpuSeconds(browser.process().pid);
      await page.evaluate(() => { for (let k = 0; k < 90; k++) window.animkit.frame(1 / 30, false); });
      perf.cpu_ms_per_frame_draw_only = (1000 * (chromiumCpuSeconds(browser.process().pid) - cpu1)) / 90;
    }
    // The native viewer side by side: CPU per frame of `animkit view --headless` at the same size
    // on one thread (difference of a 100- and a 10-frame run, so loading is not counted). Both
    // draw CesiumMan's JPEG texture.
    const selfChildCpu = () => { const f = fs.readFileSync('/proc/self/stat', 'utf8').split(') ')[1].split(' '); return (Number(f[13]) + Number(f[14])) / 100; };
    const nativeCpu = (frames) => {
      const c0 = selfChildCpu();
      execFileSync(cli, ['view', cesium, '--headless', '--size', '960x600', '--threads', '1', '--frames', String(frames)], { stdio: 'ignore' });
      return selfChildCpu() - c0;
    };
    if (!perf.error) {
      perf.native_cpu_ms_per_frame = (1000 * (nativeCpu(100) - nativeCpu(10))) / 90;
      perf.cpu_ratio_page_to_native = perf.cpu_ms_per_frame / perf.native_cpu_ms_per_frame;
      console.log(`info native animkit view, same frame: ${perf.native_cpu_ms_per_frame.toFixed(2)} ms CPU a frame; page / native CPU ${perf.cpu_ratio_page_to_native.toFixed(2)}`);
    }
    results.cesiumman_960x600 = perf;
    if (perf.error) check(false, 'CesiumMan loads in the page', perf.error);
    else console.log(`info CesiumMan 960x600: median ${perf.median_ms.toFixed(2)} ms a frame (${(1000 / perf.median_ms).toFixed(1)} fps), ` +
                     `mean ${perf.mean_ms.toFixed(2)} ms, p90 ${perf.p90_ms.toFixed(2)} ms; Chromium CPU ${perf.cpu_ms_per_frame.toFixed(2)} ms a frame ` +
                     `(${(1000 / perf.cpu_ms_per_frame).toFixed(1)} fps on an idle core), of which the module ${perf.cpu_ms_per_frame_draw_only.toFixed(2)} ms; sample ${perf.stats.sampleMs.toFixed(2)}, ` +
                     `skin ${perf.stats.skinMs.toFixed(2)}, raster ${perf.stats.rasterMs.toFixed(2)} ms (averages since opening)`);
    await shot('08_cesiumman_timed.png');
  } else {
    console.log('info CesiumMan.glb not given: no frame-time measurement');
  }

  check(offsite.length === 0, 'the page requested nothing beyond its own files', offsite.join(' '));
  check(consoleErrors.length === 0, 'no console errors', consoleErrors.join(' | '));
} finally {
  await browser.close();
  server.close();
}
fs.writeFileSync(path.join(outDir, 'results.json'), JSON.stringify(results, null, 1));
console.log(failures ? `${failures} check(s) failed` : 'all checks passed');
process.exit(failures ? 1 : 0);
