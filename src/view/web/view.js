// sedbridge view: the page. Gets the fingertip meshes once (/api/mesh), then frames: the latest
// at once (/api/frame) and the rest as Server-Sent Events (/api/events). A frame carries every
// finger the bus has (a hand's channels end in _<FINGER>); each gets a panel (taxels, display,
// timelines) and the 3-D panel shows the finger picked in its menu. It sends nothing to the
// bridge; the only request it makes is the log playback (/api/control).

const $ = (id) => document.getElementById(id);
const state = $('state');
let THREE = null, OrbitControls = null, tip = null, sedScale = 1000;
let latest = null, drawn = 0, frames = 0;
const panels = new Map();  // finger name -> its panel's elements and drawing state
const fingerLabel = (name) => (name ? name.toLowerCase() : 'finger');

// Colour map (viridis stops) over [0, 1], clamped; NaN (a vertex the field does not carry) grey.
const STOPS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
function colour(u) {
  if (!Number.isFinite(u)) return [150, 150, 150];
  u = Math.min(1, Math.max(0, u)) * (STOPS.length - 1);
  const i = Math.min(STOPS.length - 2, Math.floor(u)), f = u - i;
  return STOPS[i].map((c, k) => Math.round(c + f * (STOPS[i + 1][k] - c)));
}
const css = (rgb) => `rgb(${rgb[0]},${rgb[1]},${rgb[2]})`;
const fmt = (v, d = 3) => (v === null || v === undefined || !Number.isFinite(v) ? '–' : Number(v).toPrecision(d));

function missing(text) {
  const m = $('missing');
  m.hidden = false;
  m.textContent += (m.textContent ? '\n' : '') + text;
}

function loadScript(src) {
  return new Promise((ok, fail) => {
    const s = document.createElement('script');
    s.src = src; s.onload = ok; s.onerror = fail;
    document.head.appendChild(s);
  });
}

async function loadLibraries() {
  const run = 'run tools/setup.sh (npm ci in tools/view-web) and rebuild (target sedbridge_view_web)';
  try {
    THREE = await import('three');
    OrbitControls = (await import('./vendor/OrbitControls.js')).OrbitControls;
  } catch (e) {
    THREE = null;
    missing('three.js is not in vendor/: ' + run + '. The 3-D panel is off.');
  }
  try { await loadScript('vendor/uPlot.iife.min.js'); } catch (e) {
    missing('uPlot is not in vendor/: ' + run + '. The timelines are off.');
  }
  state.dataset.libs = THREE && window.uPlot ? 'ok' : 'missing';
}

// ---------- pad panels (taxels, display): pad frame x right, y (toward the tip) up ----------
function padTransform(canvas, xs, ys, margin_mm) {
  const x0 = Math.min(...xs) - margin_mm, x1 = Math.max(...xs) + margin_mm;
  const y0 = Math.min(...ys) - margin_mm, y1 = Math.max(...ys) + margin_mm;
  const s = Math.min(canvas.width / (x1 - x0), canvas.height / (y1 - y0));
  const ox = (canvas.width - s * (x1 - x0)) / 2, oy = (canvas.height - s * (y1 - y0)) / 2;
  return { s, X: (x) => ox + s * (x - x0), Y: (y) => canvas.height - oy - s * (y - y0) };
}
function rowLayout(n) { return { x_mm: [...Array(n).keys()].map((i) => i * 3), y_mm: Array(n).fill(0), cell_w_mm: 2.5, cell_h_mm: 2.5 }; }

function arrow(g, x0, y0, x1, y1, colour, width, head) {
  if (Math.hypot(x1 - x0, y1 - y0) < 1) return;
  g.strokeStyle = colour; g.fillStyle = colour; g.lineWidth = width;
  g.beginPath(); g.moveTo(x0, y0); g.lineTo(x1, y1); g.stroke();
  const a = Math.atan2(y1 - y0, x1 - x0);
  g.beginPath(); g.moveTo(x1, y1); g.lineTo(x1 - head * Math.cos(a - 0.4), y1 - head * Math.sin(a - 0.4));
  g.lineTo(x1 - head * Math.cos(a + 0.4), y1 - head * Math.sin(a + 0.4)); g.closePath(); g.fill();
}

function drawTaxels(P, f) {
  const c = P.taxels, g = c.getContext('2d');
  g.fillStyle = '#1b1b1b'; g.fillRect(0, 0, c.width, c.height);
  const scan = f.scan;
  if (!scan) { g.fillStyle = '#888'; g.fillText('no tactile scan yet', 10, 20); return; }
  const p = scan.pressure_kPa, L = scan.layout || rowLayout(p.length);
  const w = L.cell_w_mm || 2, h = L.cell_h_mm || 2;
  const T = padTransform(c, L.x_mm, L.y_mm, Math.max(w, h));
  const taxelTop = P.taxelTop = Math.max(P.taxelTop, ...p.filter(Number.isFinite));
  const used = f.contact && f.contact.taxel_used.length === p.length ? f.contact.taxel_used : null;
  g.font = '11px system-ui'; g.textAlign = 'center'; g.textBaseline = 'middle';
  p.forEach((v, i) => {
    const x = T.X(L.x_mm[i]), y = T.Y(L.y_mm[i]), pw = T.s * w * 0.92, ph = T.s * h * 0.92;
    g.fillStyle = scan.valid[i] ? css(colour(v / taxelTop)) : '#444';
    g.fillRect(x - pw / 2, y - ph / 2, pw, ph);
    if (used && (used[i] === 0 || used[i] === 3)) { g.strokeStyle = '#f96'; g.lineWidth = 2; g.strokeRect(x - pw / 2, y - ph / 2, pw, ph); }
    g.fillStyle = v / taxelTop > 0.6 ? '#000' : '#fff';
    g.fillText(scan.valid[i] ? fmt(v, 3) : 'invalid', x, y + (scan.shear_x_kPa ? T.s * h * 0.3 : 0));
  });
  // A three-axis sensor's shear, an arrow a taxel from its centre: the largest shear seen on
  // this finger spans 0.45 of a taxel (so arrows stay on their taxel).
  const sx = scan.shear_x_kPa, sy = scan.shear_y_kPa;
  if (sx && sy) {
    P.shearTop = Math.max(P.shearTop, ...sx.map((v, i) => Math.hypot(v, sy[i])).filter(Number.isFinite));
    const per_kPa = 0.45 * Math.min(w, h) / P.shearTop;
    p.forEach((v, i) => {
      if (!scan.valid[i] || !Number.isFinite(sx[i]) || !Number.isFinite(sy[i])) return;
      arrow(g, T.X(L.x_mm[i]), T.Y(L.y_mm[i]), T.X(L.x_mm[i] + per_kPa * sx[i]), T.Y(L.y_mm[i] + per_kPa * sy[i]),
        v / taxelTop > 0.6 ? '#000' : '#fff', 1.5, 5);
    });
  }
  const k = f.contact;
  if (k && k.shape > 0) {
    g.strokeStyle = '#fff'; g.lineWidth = 2; g.setLineDash([6, 4]);
    // A sphere: its lowest point (+) and the contact patch, radius sqrt(2 R d) at the
    // indentation d the press reached (the sphere itself, R ~ 10-20 mm, would fill the pad).
    const patch = (x, y, R, d) => {
      const a = d > 0 ? Math.sqrt(2 * R * d) : 0;
      const px = T.X(x), py = T.Y(y);
      g.beginPath(); g.moveTo(px - 6, py); g.lineTo(px + 6, py); g.moveTo(px, py - 6); g.lineTo(px, py + 6); g.stroke();
      if (a > 0) { g.beginPath(); g.arc(px, py, T.s * a, 0, 2 * Math.PI); g.stroke(); }
    };
    if (k.shape === 1 || k.shape === 4) patch(k.x_mm, k.y_mm, k.radius_mm, k.indentation_mm);
    if (k.shape === 4) patch(k.x2_mm, k.y2_mm, k.radius2_mm, k.indentation_mm);
    if (k.shape === 2) {
      const a = k.yaw_deg * Math.PI / 180, half = (k.length_mm > 0 ? k.length_mm : 40) / 2;
      const dx = Math.cos(a) * half, dy = Math.sin(a) * half, nx = -Math.sin(a) * k.radius_mm, ny = Math.cos(a) * k.radius_mm;
      for (const sgn of [-1, 1]) {
        g.beginPath(); g.moveTo(T.X(k.x_mm - dx + sgn * nx), T.Y(k.y_mm - dy + sgn * ny));
        g.lineTo(T.X(k.x_mm + dx + sgn * nx), T.Y(k.y_mm + dy + sgn * ny)); g.stroke();
      }
    }
    g.setLineDash([]);
    // The contact's whole tangential force, from the contact point. 1 N = 20 mm on the pad.
    const fx = k.shear_x_N, fy = k.shear_y_N;
    if (Math.hypot(fx, fy) > 1e-4) arrow(g, T.X(k.x_mm), T.Y(k.y_mm), T.X(k.x_mm + 20 * fx), T.Y(k.y_mm + 20 * fy), '#0ff', 3, 10);
  }
  const shapes = ['no contact', 'sphere', 'rod', 'flat', 'two spheres'];
  P.contactCaption.innerHTML = `scan ${scan.sequence} (${scan.sensor_id}), colour 0–${fmt(taxelTop)} kPa` +
    (sx ? `, shear per taxel: arrows, the longest (0.45 taxel) ${fmt(P.shearTop)} kPa` : ', no per-taxel shear (normal-only sensor)') +
    (k ? `<br>contact: ${shapes[k.shape] || k.shape}, force ${fmt(k.normal_force_N)} N, shear (${fmt(k.shear_x_N, 2)}, ${fmt(k.shear_y_N, 2)}) N, ` +
      `residual ${fmt(k.residual_rms_sigma)} σ, indentation ${fmt(k.indentation_mm)} mm, total shear: cyan arrow, 1 N = 20 mm, ${k.num_taxels_used ?? k.taxel_used.filter((u) => u === 1 || u === 2).length} taxels used` +
      (k.fallback ? ' <span class="flag">FALLBACK: estimate not trusted, pressure map used</span>' : '')
       : '<br>no contact estimate on the bus');
}

function drawDisplay(P, f) {
  const c = P.display, g = c.getContext('2d');
  g.fillStyle = '#1b1b1b'; g.fillRect(0, 0, c.width, c.height);
  const d = f.display;
  if (!d) { g.fillStyle = '#888'; g.fillText('no display command yet', 10, 20); P.displayCaption.textContent = ''; return; }
  const v = d.commanded, L = d.layout || rowLayout(v.length), max = (d.layout && d.layout.max) || Math.max(1e-9, ...v);
  let pitch = Infinity;
  for (let i = 0; i < L.x_mm.length; ++i) for (let j = i + 1; j < L.x_mm.length; ++j)
    pitch = Math.min(pitch, Math.hypot(L.x_mm[i] - L.x_mm[j], L.y_mm[i] - L.y_mm[j]));
  if (!Number.isFinite(pitch) || pitch <= 0) pitch = 3;
  const T = padTransform(c, L.x_mm, L.y_mm, pitch);
  const tgt = d.target_sed_Pa, tmax = tgt ? Math.max(1e-9, ...tgt.filter(Number.isFinite)) : 1;
  g.font = '11px system-ui'; g.textAlign = 'center'; g.textBaseline = 'middle';
  v.forEach((val, i) => {
    const x = T.X(L.x_mm[i]), y = T.Y(L.y_mm[i]), r = T.s * pitch * 0.45;
    g.fillStyle = css(colour(val / max)); g.fillRect(x - r, y - r, 2 * r, 2 * r);
    if (tgt) { // the target: SED the mapping read at this site, as a ring on the same pad
      g.strokeStyle = '#fff'; g.lineWidth = 1.5; g.beginPath();
      g.arc(x, y, Math.max(1, r * 0.9 * Math.sqrt(Math.max(0, tgt[i]) / tmax)), 0, 2 * Math.PI); g.stroke();
    }
    g.fillStyle = val / max > 0.6 ? '#000' : '#fff'; g.fillText(fmt(val, 3), x, y);
  });
  const flags = ['clamped', 'stale', 'fault', 'shutdown'].filter((k) => d[k]);
  P.displayCaption.innerHTML = `${d.display_id}: commanded ${d.unit} (colour 0–${fmt(max)} ${d.unit}), command ${d.sequence}` +
    (flags.length ? ` <span class="flag">${flags.join(', ')}</span>` : '') +
    `<br>target (ring): ${tgt ? 'SED at each site, largest ' + fmt(tmax) + ' Pa (SA1_RATE_ESTIMATE)' : 'not on the bus'}`;
  drawDelivered(P, d.delivered);
}

// Target | delivered: the SED the renderer was asked for and the SED the published commands
// add by its influence model (DISPLAY_RENDERING), on the pad's side of the Merkel layer, seen
// onto the pad, on one scale (the larger of the two maxima).
function drawDelivered(P, r) {
  const canvases = [P.sedTarget, P.sedDelivered];
  for (const c of canvases) { const g = c.getContext('2d'); g.fillStyle = '#1b1b1b'; g.fillRect(0, 0, c.width, c.height); }
  if (!r) {
    P.deliveredCaption.textContent = 'not on the bus (DISPLAY_RENDERING: the bridge publishes it with inverse rendering)';
    return;
  }
  const top = Math.max(1e-9, r.max_target_sed_Pa, r.max_delivered_sed_Pa);
  [r.target_sed_Pa, r.delivered_sed_Pa].forEach((values, k) => {
    const c = canvases[k], g = c.getContext('2d'), T = padTransform(c, r.x_mm, r.y_mm, 1);
    const size = Math.max(2, T.s * 0.9);
    values.forEach((v, i) => {
      g.fillStyle = css(colour(v === null ? NaN : v / top));
      g.fillRect(T.X(r.x_mm[i]) - size / 2, T.Y(r.y_mm[i]) - size / 2, size, size);
    });
    g.fillStyle = '#ddd'; g.font = '11px system-ui'; g.textAlign = 'left'; g.textBaseline = 'top';
    g.fillText(k === 0 ? 'target' : 'delivered', 4, 4);
  });
  P.deliveredCaption.textContent = `colour 0–${fmt(top)} Pa; largest: target ${fmt(r.max_target_sed_Pa)} Pa, ` +
    `delivered ${fmt(r.max_delivered_sed_Pa)} Pa (command ${r.command_sequence}, the renderer's influence model` +
    (r.limited ? '; the safety limiter changed this command: the renderer\'s intent)' : ')');
}

// ---------- 3-D fingertip: one mesh a model (usually one, B), showing the picked finger ----------
function setupTip(meshes) {
  const el = $('tip');
  let renderer;
  try { renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true }); } catch (e) {
    missing('WebGL is not available in this browser: the 3-D panel is off.');
    state.dataset.webgl = 'no';
    return null;
  }
  state.dataset.webgl = 'yes';
  renderer.setSize(el.clientWidth || 420, el.clientHeight || 360);
  el.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1b1b1b);
  const camera = new THREE.PerspectiveCamera(40, (el.clientWidth || 420) / (el.clientHeight || 360), 0.1, 1000);
  camera.up.set(0, 1, 0);
  camera.position.set(0, -10, 40);
  const controls = new OrbitControls(camera, renderer.domElement);
  scene.add(new THREE.AmbientLight(0xffffff, 0.8));
  const light = new THREE.DirectionalLight(0xffffff, 1.5); light.position.set(10, -20, 40); scene.add(light);
  const t = { renderer, scene, camera, controls, models: [], points: null, shown: -1 };
  const geometry = (part) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(part.xyz_mm, 3));
    g.setIndex(part.triangles);
    g.computeVertexNormals();
    return g;
  };
  meshes.forEach((mesh, k) => {
    const m = { merkel: null, skin: null, n: 0 };
    if (mesh.merkel.triangles.length) {
      const g = geometry(mesh.merkel);
      m.n = mesh.merkel.xyz_mm.length / 3;
      g.setAttribute('color', new THREE.Float32BufferAttribute(new Float32Array(3 * m.n).fill(0.35), 3));
      m.merkel = new THREE.Mesh(g, new THREE.MeshLambertMaterial({ vertexColors: true, side: THREE.DoubleSide }));
      scene.add(m.merkel);
      if (k === 0) {
        g.computeBoundingSphere();
        // Looking onto the pad (down its normal, slightly from below the tip), the tip up, at
        // the pad frame's origin: where the pressing plane first touches.
        const r = g.boundingSphere.radius;
        controls.target.set(0, 0, 0);
        camera.position.set(0, -0.5 * r, 1.8 * r);
      }
    }
    if (mesh.skin.triangles.length) {
      // Two looks at one skin: opaque, coloured by the SED of the Merkel vertex beneath each
      // skin vertex (skin_merkel); or translucent over the coloured Merkel layer.
      const g = geometry(mesh.skin), n = mesh.skin.xyz_mm.length / 3;
      g.setAttribute('color', new THREE.Float32BufferAttribute(new Float32Array(3 * n).fill(0.35), 3));
      m.skin = new THREE.Mesh(g, new THREE.MeshLambertMaterial({ vertexColors: true }));
      m.veil = new THREE.Mesh(g, new THREE.MeshLambertMaterial({ color: 0xd8b4a0, transparent: true, opacity: 0.07, depthWrite: false }));
      m.skinMerkel = mesh.skin_merkel || [];
      scene.add(m.skin, m.veil);
    }
    t.models.push(m);
  });
  // Model k's surfaces as $('tip-surface') asks; -1: none (a field drawn as points).
  t.show = (k) => {
    const skin = $('tip-surface').value === 'skin';
    t.models.forEach((m, j) => {
      if (m.merkel) m.merkel.visible = j === k && !(skin && m.skin);
      if (m.skin) { m.skin.visible = j === k && skin; m.veil.visible = j === k && !skin; }
    });
    t.shown = k;
  };
  t.show(0);
  controls.update();
  const loop = () => { controls.update(); renderer.render(scene, camera); requestAnimationFrame(loop); };
  loop();
  return t;
}

// The finger the 3-D panel shows: the one picked, else the first with a SED field.
function tipFinger(frame) {
  const picked = $('tip-finger').value;
  return frame.fingers.find((f) => f.name === picked && f.sed) || frame.fingers.find((f) => f.sed) || null;
}

function drawSed(frame) {
  const f = tipFinger(frame), s = f ? f.sed : null;
  state.dataset.tipFinger = f ? f.name : '';
  state.dataset.tipSurface = $('tip-surface').value;
  $('sed-caption').innerHTML = s
    ? `${frame.fingers.length > 1 ? fingerLabel(f.name) + ': ' : ''}model ${s.model_id}, ${s.num_vertices} Merkel vertices (${s.matched_vertices} on the mesh, the rest grey)` +
      ($('tip-surface').value === 'skin' ? ', drawn on the skin above them (skin with no Merkel vertex beneath: plain),' : ',') +
      ` SED ${fmt(s.min_finite_Pa)}–${fmt(s.max_finite_Pa)} Pa, step at ${((s.utime - (f.scan ? f.scan.utime : s.utime)) / 1e3).toFixed(1)} ms from the scan shown`
    : 'no SED field yet';
  if (!tip || !s) return;
  if (s.on_mesh_Pa && s.mesh >= 0 && tip.models[s.mesh] && tip.models[s.mesh].merkel) {
    if (tip.points) { tip.scene.remove(tip.points); tip.points = null; }
    tip.show(s.mesh);
    const m = tip.models[s.mesh], tmp = new THREE.Color();
    // The scale's colours are sRGB; three.js lights in linear space.
    const paint = (col, v, rgb) => { tmp.setRGB(rgb[0] / 255, rgb[1] / 255, rgb[2] / 255, THREE.SRGBColorSpace); col.setXYZ(v, tmp.r, tmp.g, tmp.b); };
    const sedAt = (v) => colour(s.on_mesh_Pa[v] === null ? NaN : s.on_mesh_Pa[v] / sedScale);
    const col = m.merkel.geometry.getAttribute('color');
    for (let v = 0; v < m.n; ++v) paint(col, v, sedAt(v));
    col.needsUpdate = true;
    let coloured = 0;
    if (m.skin) {
      // Skin with no Merkel vertex beneath (the nail side) in a plain skin tone.
      const skinCol = m.skin.geometry.getAttribute('color');
      m.skinMerkel.forEach((k, v) => {
        const finite = k >= 0 && s.on_mesh_Pa[k] !== null;
        coloured += finite;
        paint(skinCol, v, k >= 0 ? sedAt(k) : [140, 122, 112]);
      });
      skinCol.needsUpdate = true;
    }
    state.dataset.skinColoured = String(coloured);
  } else if (s.points) {
    tip.show(-1);
    if (tip.points) tip.scene.remove(tip.points);
    const g = new THREE.BufferGeometry(), n = s.points.x_mm.length, pos = new Float32Array(3 * n), col = new Float32Array(3 * n);
    for (let k = 0; k < n; ++k) {
      pos.set([s.points.x_mm[k], s.points.y_mm[k], s.points.z_mm[k]], 3 * k);
      col.set(colour(s.points.sed_Pa[k] / sedScale).map((c) => c / 255), 3 * k);
    }
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3)); g.setAttribute('color', new THREE.BufferAttribute(col, 3));
    tip.points = new THREE.Points(g, new THREE.PointsMaterial({ size: 0.4, vertexColors: true }));
    tip.scene.add(tip.points);
  }
}

// ---------- timelines ----------
function drawTimelines(P, f, live) {
  if (window.uPlot) {
    const specs = [['force_N', 'force [N]', '#6cf'], ['peak_sed_Pa', 'peak Merkel SED [Pa]', '#fc6'], ['latency_ms', 'per-scan latency [ms]', '#9f9']];
    for (const [key, label, stroke] of specs) {
      const s = f.timeline[key];
      if (!P.plots[key]) {
        const el = document.createElement('div');
        P.timelines.appendChild(el);
        P.plots[key] = new uPlot({ width: 360, height: 90, scales: { x: { time: false } }, legend: { show: true },
          axes: [{ stroke: '#aaa', grid: { stroke: '#333' } }, { stroke: '#aaa', grid: { stroke: '#333' }, size: 60 }],
          series: [{ label: 't [s]' }, { label, stroke, width: 1.5 }] }, [[], []], el);
      }
      P.plots[key].setData([s.t_s, s.v.map((v) => (v === null ? undefined : v))]);
    }
  }
  const b = f.status;
  P.statusCaption.textContent = b
    ? `bridge status: scans ${fmt(b.scan_rate_Hz)} Hz, latency p50 ${fmt(b.latency_p50_ms)} ms, p99 ${fmt(b.latency_p99_ms)} ms, dropped ${b.scans_dropped}` +
      (b.fault_state ? `, FAULT ${b.fault_state}: ${b.fault_message}` : '')
    : 'no bridge status on the bus';
  const lat = f.timeline.latency_ms.v;
  if (!live && lat.length && lat.every((v) => v === 0))
    P.statusCaption.textContent += ' (per-scan latency is 0 on a replay\'s log clock; the status line has the replay\'s measured percentiles)';
}

// ---------- fingers ----------
function panelOf(name) {
  let P = panels.get(name);
  if (P) return P;
  const root = $('finger-template').content.firstElementChild.cloneNode(true);
  root.dataset.finger = name;
  root.querySelector('.finger-title').textContent = name ? `Finger: ${fingerLabel(name)}` : 'Finger';
  $('fingers').appendChild(root);
  const q = (sel) => root.querySelector(sel);
  P = { root, taxels: q('.taxels'), display: q('.display'), timelines: q('.timelines'), contactCaption: q('.contact-caption'),
    displayCaption: q('.display-caption'), sedTarget: q('.sed-target'), sedDelivered: q('.sed-delivered'),
    deliveredCaption: q('.delivered-caption'), statusCaption: q('.status-caption'), state: q('.finger-state'), plots: {}, taxelTop: 1, shearTop: 0.1 };
  panels.set(name, P);
  const menu = $('tip-finger'), option = document.createElement('option');
  option.value = name; option.textContent = fingerLabel(name);
  menu.appendChild(option);
  $('tip-finger-label').hidden = menu.options.length < 2;
  return P;
}

// What a finger's panel shows, as data-attributes of `el`.
function writeFingerState(el, f) {
  const d = el.dataset;
  d.finger = f.name;
  d.scanUtime = f.scan ? String(f.scan.utime) : '';
  d.sensorId = f.scan ? f.scan.sensor_id : '';
  d.taxels = f.scan ? f.scan.pressure_kPa.map(String).join(',') : '';
  d.shearX = f.scan && f.scan.shear_x_kPa ? f.scan.shear_x_kPa.map(String).join(',') : '';
  d.shearY = f.scan && f.scan.shear_y_kPa ? f.scan.shear_y_kPa.map(String).join(',') : '';
  d.sedUtime = f.sed ? String(f.sed.utime) : '';
  d.sedMin = f.sed ? String(f.sed.min_finite_Pa) : '';
  d.sedMax = f.sed ? String(f.sed.max_finite_Pa) : '';
  d.sedMatched = f.sed ? String(f.sed.matched_vertices) : '';
  d.commandSequence = f.display ? String(f.display.sequence) : '';
  d.displayId = f.display ? f.display.display_id : '';
  d.commanded = f.display ? f.display.commanded.map(String).join(',') : '';
  const r = f.display && f.display.delivered;
  d.renderingSequence = r ? String(r.command_sequence) : '';
  d.targetMax = r ? String(r.max_target_sed_Pa) : '';
  d.deliveredMax = r ? String(r.max_delivered_sed_Pa) : '';
  d.contactFlag = f.contact ? (f.contact.fallback ? 'fallback' : 'trusted') : '';
  d.contactResidual = f.contact ? String(f.contact.residual_rms_sigma) : '';
}

// ---------- frames ----------
function writeState(f) {
  const d = state.dataset;
  d.frames = String(++frames);
  d.version = String(f.version);
  d.positionS = String(f.playback.position_s);
  d.sedScale = String(f.sed_scale_Pa);
  d.fingers = f.fingers.map((g) => g.name).join(',');
  // The first finger's, at the top (one-finger scripts read these).
  writeFingerState(state, f.fingers[0] || { name: '' });
}

function showPlayback(p) {
  $('source').textContent = (p.live ? 'live: ' : 'log: ') + p.source;
  if (p.live) return;
  $('controls').hidden = false;
  $('play').textContent = p.playing ? 'pause' : 'play';
  const slider = $('slider');
  slider.max = String(p.duration_s);
  if (document.activeElement !== slider) slider.value = String(p.position_s);
  $('time').textContent = `${p.position_s.toFixed(3)} / ${p.duration_s.toFixed(3)} s`;
}

// Rates over the last 2 s of wall time, written to #state for measuring the page.
const stamps = { frame: [], draw: [] };
function count(kind) {
  const now = performance.now(), a = stamps[kind];
  a.push(now);
  while (a.length && a[0] < now - 2000) a.shift();
  state.dataset[kind + 'Hz'] = (a.length / 2).toFixed(1);
}

function take(f) {
  latest = f;
  count('frame');
  sedScale = f.sed_scale_Pa;
  writeState(f);
}

function draw() {
  const view = latest ? [latest.version, latest.playback.position_s, $('tip-finger').value, $('tip-surface').value].join(':') : '';
  if (latest && drawn !== view) {
    const f = latest;
    drawn = view;
    showPlayback(f.playback);
    for (const finger of f.fingers) {
      const P = panelOf(finger.name);
      drawTaxels(P, finger);
      drawDisplay(P, finger);
      drawTimelines(P, finger, f.playback.live);
      writeFingerState(P.state, finger);
    }
    drawSed(f);
    state.dataset.drawn = String(f.version);
    state.dataset.panels = String(panels.size);
    count('draw');
  }
}

const control = (body) => fetch('api/control', { method: 'POST', body });
$('play').onclick = () => control(latest && latest.playback.playing ? 'pause' : 'play');
$('slider').onchange = (e) => control('seek ' + e.target.value);
$('speed').onchange = (e) => control('speed ' + e.target.value);

async function main() {
  await loadLibraries();
  const mesh = await (await fetch('api/mesh')).json();
  sedScale = mesh.sed_scale_Pa;
  $('sed-hi').textContent = fmt(sedScale, 4) + ' Pa (fixed)';
  $('sed-lo').textContent = '0 Pa';
  $('sed-bar').style.background = `linear-gradient(to right, ${STOPS.map((s) => css(s)).join(',')})`;
  for (const m of mesh.meshes) if (m.error) missing(`no fingertip mesh for model ${m.model_id} (${m.error}): SED drawn as points`);
  state.dataset.meshVertices = mesh.meshes.map((m) => String(m.merkel.xyz_mm.length / 3)).join(',');
  if (THREE) tip = setupTip(mesh.meshes);
  // The latest frame at once, then the stream.
  for (let tries = 0; tries < 50; ++tries) {
    const r = await fetch('api/frame');
    if (r.ok) { take(await r.json()); break; }
    await new Promise((ok) => setTimeout(ok, 100));
  }
  draw();
  // ?close-after=N: stop streaming after N frames (headless tests, whose browser waits for
  // every open request before it writes the page out).
  const closeAfter = Number(new URLSearchParams(location.search).get('close-after') || 0);
  let streamed = 0;
  const events = new EventSource('api/events');
  events.addEventListener('frame', (e) => {
    take(JSON.parse(e.data));
    $('conn').textContent = 'streaming';
    state.dataset.streamed = String(++streamed);
    if (closeAfter > 0 && streamed >= closeAfter) { events.close(); $('conn').textContent = 'closed'; draw(); }
  });
  events.onerror = () => { $('conn').textContent = 'reconnecting'; };
  const tick = () => { draw(); requestAnimationFrame(tick); };
  requestAnimationFrame(tick);
  state.dataset.ready = 'yes';
}
main();
