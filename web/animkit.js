// animkit in a browser: loads animkit.wasm (built by `make web`, docs/web.md), gives it the few
// WASI calls it makes (console output, clocks; no files, no network), and drives the viewer of
// web/animkit_web.c: canvas mouse and keys in, animkit's own RGBA framebuffer out to the canvas.
// window.animkit exposes the same entry points to scripts (tests/web/ drives it from Chromium).
'use strict';

(function () {
  const ERRNO = { SUCCESS: 0, BADF: 8, NOENT: 44, NOSYS: 52, SPIPE: 70 };
  const KEY = { Escape: 256, ArrowLeft: 257, ArrowRight: 258, ArrowUp: 259, ArrowDown: 260, Tab: 9, ' ': 32 };

  let wasm = null; // the instance's exports
  const enc = new TextEncoder();
  const dec = new TextDecoder();
  const lineBuf = { 1: '', 2: '' };

  function mem() { return new DataView(wasm.memory.buffer); }
  function u8() { return new Uint8Array(wasm.memory.buffer); }

  // ---- the WASI calls the module imports (wasi_snapshot_preview1) ----
  const wasi = {
    fd_write(fd, iovs, iovsLen, nwrittenPtr) {
      const dv = mem();
      let n = 0, text = '';
      for (let i = 0; i < iovsLen; i++) {
        const p = dv.getUint32(iovs + 8 * i, true), l = dv.getUint32(iovs + 8 * i + 4, true);
        text += dec.decode(u8().subarray(p, p + l));
        n += l;
      }
      dv.setUint32(nwrittenPtr, n, true);
      if (fd !== 1 && fd !== 2) return ERRNO.BADF;
      lineBuf[fd] += text;
      let k;
      while ((k = lineBuf[fd].indexOf('\n')) >= 0) {
        const line = lineBuf[fd].slice(0, k);
        lineBuf[fd] = lineBuf[fd].slice(k + 1);
        if (fd === 2) { console.error(line); api.onMessage(line, true); } else { console.log(line); }
      }
      return ERRNO.SUCCESS;
    },
    clock_time_get(id, precision, outPtr) {
      const ns = id === 0 ? BigInt(Date.now()) * 1000000n : BigInt(Math.round(performance.now() * 1e6));
      mem().setBigUint64(outPtr, ns, true);
      return ERRNO.SUCCESS;
    },
    fd_fdstat_get(fd, ptr) {
      if (fd > 2) return ERRNO.BADF;
      const dv = mem();
      dv.setUint8(ptr, 2); // character device
      dv.setUint16(ptr + 2, 0, true);
      dv.setBigUint64(ptr + 8, 0xffffffffffffffffn, true);
      dv.setBigUint64(ptr + 16, 0xffffffffffffffffn, true);
      return ERRNO.SUCCESS;
    },
    fd_fdstat_set_flags(fd) { return fd > 2 ? ERRNO.BADF : ERRNO.SUCCESS; },
    fd_close(fd) { return fd > 2 ? ERRNO.BADF : ERRNO.SUCCESS; },
    fd_seek(fd) { return fd > 2 ? ERRNO.BADF : ERRNO.SPIPE; },
    fd_read() { return ERRNO.BADF; },
    fd_filestat_get() { return ERRNO.BADF; },
    fd_prestat_get() { return ERRNO.BADF; }, // no preopened directories: the page has no files
    fd_prestat_dir_name() { return ERRNO.BADF; },
    path_open() { return ERRNO.NOENT; },
    path_filestat_get() { return ERRNO.NOENT; },
    proc_exit(code) { throw new Error('animkit exited with status ' + code); },
  };

  // ---- strings and buffers into the module ----
  function withString(s, fn) {
    const b = enc.encode(s + '\0');
    const p = wasm.akw_alloc(b.length);
    u8().set(b, p);
    try { return fn(p, b.length - 1); } finally { wasm.akw_free(p); }
  }
  function cString(p) {
    const a = u8();
    let e = p;
    while (a[e]) e++;
    return dec.decode(a.subarray(p, e));
  }
  function floats(p, n) { return p ? Array.from(new Float32Array(wasm.memory.buffer, p, n)) : null; }

  // ---- texture images: the browser decodes them, the library samples them ----
  // The encoded images of a glTF file (.glb, or .gltf with data: URIs): [{ bytes, mime }] for
  // every images[i] held in a bufferView or a data: URI. Anything malformed gives no image (the
  // library's glTF reader then reports the file's problem itself).
  function gltfEncodedImages(bytes) {
    try {
      const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      let json, bin = null;
      if (bytes.length >= 20 && dv.getUint32(0, true) === 0x46546c67) { // "glTF": GLB
        const total = Math.min(dv.getUint32(8, true), bytes.length);
        for (let off = 12; off + 8 <= total;) {
          const len = dv.getUint32(off, true), type = dv.getUint32(off + 4, true);
          if (off + 8 + len > total) break;
          const chunk = bytes.subarray(off + 8, off + 8 + len);
          if (type === 0x4e4f534a && !json) json = JSON.parse(dec.decode(chunk));
          else if (type === 0x004e4942 && !bin) bin = chunk;
          off += 8 + ((len + 3) & ~3);
        }
      } else {
        json = JSON.parse(dec.decode(bytes));
      }
      if (!json || !Array.isArray(json.images)) return [];
      const dataUri = (uri) => {
        const m = /^data:([^;,]*)(;base64)?,(.*)$/s.exec(uri || '');
        if (!m || !m[2]) return null;
        return { mime: m[1], bytes: Uint8Array.from(atob(m[3]), (c) => c.charCodeAt(0)) };
      };
      const buffers = (json.buffers || []).map((b, i) => (b && b.uri ? (dataUri(b.uri) || {}).bytes : i === 0 ? bin : null));
      const out = [];
      for (const im of json.images) {
        if (!im) continue;
        if (typeof im.uri === 'string') {
          const d = dataUri(im.uri);
          if (d) out.push({ bytes: d.bytes, mime: im.mimeType || d.mime });
        } else if (Number.isInteger(im.bufferView)) {
          const bv = (json.bufferViews || [])[im.bufferView], buf = bv && buffers[bv.buffer];
          const o = (bv && bv.byteOffset) || 0, n = bv && bv.byteLength;
          if (buf && Number.isInteger(n) && o + n <= buf.length) out.push({ bytes: buf.subarray(o, o + n), mime: im.mimeType });
        }
      }
      return out;
    } catch (e) {
      return [];
    }
  }
  // Decode them to RGBA8 with the browser's decoders (PNG, JPEG): createImageBitmap with no
  // colour-space conversion and no premultiplication, drawn onto an OffscreenCanvas and read
  // back. (The 2D canvas keeps premultiplied pixels, so a PNG's partly transparent texels can
  // come back a unit off; opaque ones, and every JPEG, come back as decoded.) An image the
  // browser cannot decode is left out: the library then warns and draws its meshes untextured.
  async function decodeImages(bytes) {
    const out = [];
    for (const im of gltfEncodedImages(bytes)) {
      const sig = im.bytes;
      const mime = sig[0] === 0x89 && sig[1] === 0x50 ? 'image/png' : sig[0] === 0xff && sig[1] === 0xd8 ? 'image/jpeg' : null;
      if (!mime) continue;
      try {
        const bmp = await createImageBitmap(new Blob([im.bytes], { type: mime }), { premultiplyAlpha: 'none', colorSpaceConversion: 'none' });
        const c = new OffscreenCanvas(bmp.width, bmp.height).getContext('2d', { willReadFrequently: true });
        c.drawImage(bmp, 0, 0);
        const rgba = new Uint8Array(c.getImageData(0, 0, bmp.width, bmp.height).data.buffer);
        out.push({ encoded: im.bytes, rgba, width: bmp.width, height: bmp.height });
        bmp.close();
      } catch (e) {
        console.warn('animkit: a texture image could not be decoded: ' + e.message);
      }
    }
    return out;
  }

  // ---- the page ----
  let canvas = null, ctx = null, running = true, last = 0;
  const frameMs = []; // wall time of akw_frame + putImageData, the last 240 frames

  const api = {
    ready: null,
    version: 1,
    onMessage(text, isError) {
      const el = document.getElementById('message');
      if (el) { el.textContent = text; el.className = isError ? 'error' : ''; }
    },
    error() { return cString(wasm.akw_error()); },
    open(what, width, height) {
      const w = width || canvas.width, h = height || canvas.height;
      const rc = withString(what, (p) => wasm.akw_open(p, w, h));
      if (rc !== 0) { const e = api.error(); api.onMessage(e, true); console.warn('animkit: ' + e); return false; }
      canvas.width = w; canvas.height = h;
      api.current = what;
      api.onMessage('', false);
      return true;
    },
    // a file's bytes (a .glb/.gltf/.bvh): its texture images decoded by the browser first
    // (decodeImages), then handed to the module with the file; resolves to open()'s result
    // (options.textures false: without them, as a build with no decoder draws it)
    async openBytes(name, bytes, options = {}) {
      const images = options.textures === false ? [] : await decodeImages(bytes);
      const p = wasm.akw_alloc(bytes.length);
      u8().set(bytes, p);
      const rc = withString(name, (n) => wasm.akw_file_set(p, bytes.length, n));
      wasm.akw_free(p);
      if (rc !== 0) { api.onMessage(api.error(), true); return false; }
      for (const im of images) {
        const pe = wasm.akw_alloc(im.encoded.length), pr = wasm.akw_alloc(im.rgba.length);
        u8().set(im.encoded, pe);
        u8().set(im.rgba, pr);
        const r = wasm.akw_image_add(pe, im.encoded.length, pr, im.width, im.height);
        wasm.akw_free(pe);
        wasm.akw_free(pr);
        if (r !== 0) console.warn('animkit: ' + api.error());
      }
      api.imagesGiven = images.length;
      return api.open('file:');
    },
    imagesGiven: 0,
    imagesServed() { return wasm.akw_images_served(); },
    // texture t of the open scene: { width, height, fnv1a } of its RGBA8 pixels, or null
    textureInfo(t) { const p = wasm.akw_texture_info(t); return p ? (([w, h, f]) => ({ width: w, height: h, fnv1a: f }))(Array.from(new Float64Array(wasm.memory.buffer, p, 3))) : null; },
    // one frame: advance dt seconds, draw, show (present false: draw only, for timing the
    // module alone); returns the milliseconds it took
    frame(dt, present = true) {
      const t0 = performance.now();
      const p = wasm.akw_frame(dt);
      if (!p) { api.onMessage(api.error(), true); return -1; }
      if (!present) return performance.now() - t0;
      const w = wasm.akw_width(), h = wasm.akw_height();
      if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
      ctx.putImageData(new ImageData(new Uint8ClampedArray(wasm.memory.buffer, p, w * h * 4), w, h), 0, 0);
      const ms = performance.now() - t0;
      frameMs.push(ms);
      if (frameMs.length > 240) frameMs.shift();
      return ms;
    },
    event(type, key, button, x, y, dy, shift) { wasm.akw_event(type, key | 0, button | 0, x || 0, y || 0, dy || 0, shift ? 1 : 0); },
    key(k) { api.event(0, typeof k === 'string' ? (KEY[k] || k.toLowerCase().charCodeAt(0)) : k); },
    setRunning(on) { running = !!on; if (running) { last = 0; requestAnimationFrame(loop); } },
    frameTimes() { return frameMs.slice(); },
    method() { return wasm.akw_method(); }, // 0 LBS, 1 DQS, 2 CoR, 3 side by side
    time() { return wasm.akw_time(); },
    duration() { return wasm.akw_duration(); },
    setTime(t) { wasm.akw_set_time(t); },
    jointCount() { return wasm.akw_joint_count(); },
    jointFind(name) { return withString(name, (p) => wasm.akw_joint_find(p)); },
    jointScreen(j) { return floats(wasm.akw_joint_screen(j), 2); },
    ikEffector() { return wasm.akw_ik_effector(); },
    ikTarget() { return floats(wasm.akw_ik_target(), 3); },
    ikEffectorPosition() { return floats(wasm.akw_ik_effector_position(), 3); },
    stats() { return { sampleMs: wasm.akw_stats(0), skinMs: wasm.akw_stats(1), rasterMs: wasm.akw_stats(2), frames: wasm.akw_stats(3) }; },
    // a cloth scene file's text stepped `steps` times (-1: the scene's count); positions as floats
    clothRun(json, steps) {
      const b = enc.encode(json);
      const p = wasm.akw_alloc(b.length);
      u8().set(b, p);
      const rc = wasm.akw_cloth_run(p, b.length, steps);
      wasm.akw_free(p);
      if (rc !== 0) throw new Error(api.error());
      return floats(wasm.akw_cloth_positions(), 3 * wasm.akw_cloth_vertex_count());
    },
    wasmBytes: 0,
  };
  window.animkit = api;

  function loop(now) {
    if (!running) return;
    const dt = last ? (now - last) / 1000 : 1 / 60;
    last = now;
    if (api.frame(dt) >= 0) updateControls();
    requestAnimationFrame(loop);
  }

  function canvasXY(e) {
    const r = canvas.getBoundingClientRect();
    return [(e.clientX - r.left) * canvas.width / r.width, (e.clientY - r.top) * canvas.height / r.height];
  }

  let scrubbing = false;
  function updateControls() {
    const fps = document.getElementById('fps');
    if (fps && frameMs.length) {
      const avg = frameMs.reduce((a, b) => a + b, 0) / frameMs.length;
      fps.textContent = avg.toFixed(1) + ' ms a frame (' + (1000 / avg).toFixed(0) + ' fps of drawing)';
    }
    const slider = document.getElementById('time');
    const d = api.duration();
    slider.disabled = !(d > 0);
    if (!scrubbing && d > 0) slider.value = String(Math.round(1000 * api.time() / d));
    for (const b of document.querySelectorAll('[data-method]')) b.classList.toggle('on', Number(b.dataset.method) === api.method());
  }

  function wire() {
    canvas = document.getElementById('view');
    ctx = canvas.getContext('2d');
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('mousedown', (e) => {
      const [x, y] = canvasXY(e);
      api.event(1, 0, e.button === 0 ? 1 : e.button === 1 ? 2 : 3, x, y, 0, e.shiftKey);
      e.preventDefault();
    });
    window.addEventListener('mousemove', (e) => { const [x, y] = canvasXY(e); api.event(2, 0, 0, x, y); });
    window.addEventListener('mouseup', (e) => { const [x, y] = canvasXY(e); api.event(3, 0, e.button === 0 ? 1 : e.button === 1 ? 2 : 3, x, y); });
    canvas.addEventListener('wheel', (e) => { api.event(4, 0, 0, 0, 0, -Math.sign(e.deltaY)); e.preventDefault(); }, { passive: false });
    window.addEventListener('keydown', (e) => {
      if (e.target && (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT') && e.key !== 'Escape') return;
      if (e.ctrlKey || e.metaKey || e.altKey) return;
      let k = KEY[e.key];
      if (k === undefined && e.key.length === 1) k = e.key.toLowerCase().charCodeAt(0);
      if (k === undefined) return;
      api.event(0, k);
      e.preventDefault();
    });
    document.getElementById('scene').addEventListener('change', (e) => {
      const v = e.target.value;
      if (v.startsWith('asset:')) {
        const name = v.slice(6), b64 = (window.ANIMKIT_ASSETS || {})[name];
        if (!b64) { api.onMessage(name + ' is not bundled in this build', true); return; }
        api.openBytes(name, Uint8Array.from(atob(b64), (c) => c.charCodeAt(0)));
      } else {
        api.open(v);
      }
      e.target.blur();
    });
    for (const b of document.querySelectorAll('[data-key]'))
      b.addEventListener('click', () => { api.key(b.dataset.key === 'space' ? ' ' : b.dataset.key); b.blur(); });
    const slider = document.getElementById('time');
    slider.addEventListener('input', () => { scrubbing = true; api.setTime(api.duration() * Number(slider.value) / 1000); });
    slider.addEventListener('change', () => { scrubbing = false; slider.blur(); });
    const loadFile = (f) => f.arrayBuffer().then((buf) => api.openBytes(f.name, new Uint8Array(buf)));
    document.body.addEventListener('dragover', (e) => { e.preventDefault(); document.body.classList.add('drop'); });
    document.body.addEventListener('dragleave', () => document.body.classList.remove('drop'));
    document.body.addEventListener('drop', (e) => {
      e.preventDefault();
      document.body.classList.remove('drop');
      if (e.dataTransfer.files.length) loadFile(e.dataTransfer.files[0]);
    });
    document.getElementById('file').addEventListener('change', (e) => { if (e.target.files.length) loadFile(e.target.files[0]); });
  }

  async function start() {
    wire();
    const res = await fetch('animkit.wasm');
    if (!res.ok) throw new Error('animkit.wasm: HTTP ' + res.status);
    const bytes = await res.arrayBuffer();
    api.wasmBytes = bytes.byteLength;
    const { instance } = await WebAssembly.instantiate(bytes, { wasi_snapshot_preview1: wasi });
    wasm = instance.exports;
    wasm._initialize();
    const first = new URLSearchParams(location.search).get('open') || 'builtin:humanoid';
    if (!api.open(first)) api.open('builtin:humanoid');
    const sel = document.getElementById('scene');
    if ([...sel.options].some((o) => o.value === first)) sel.value = first;
    if (new URLSearchParams(location.search).get('paused') === '1') running = false;
    else requestAnimationFrame(loop);
  }

  api.ready = new Promise((resolve, reject) => {
    const go = () => start().then(resolve, (e) => { console.error('animkit: ' + e.message); api.onMessage(e.message, true); reject(e); });
    if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', go); else go();
  });
})();
