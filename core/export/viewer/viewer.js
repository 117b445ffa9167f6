// bimart's viewer page (docs/outputs.md): plays the .glb scenes embedded in the page with
// three.js's glTF loader and animation mixer. Bundled with three.js into one script by
// build_bundle.sh; core/export/viewer_page.cc inlines that script and the data.
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const CONTACT_COLORS = [new THREE.Color(0.9, 0.05, 0.05), new THREE.Color(0.55, 0.05, 0.85)];  // left, right

// Timeline colours of the marks of a directed run (core/export/viewer_marks.h): the parts'
// colours of the scene, grey for "any", dark for "off the object", the hands' for pins.
const MARK_COLORS = { top: '#f28c33', bottom: '#4d80d9', any: '#9a9a9a', none: '#333333', redraw: '#2ca02c',
                      contacts: '#a8d5a8' };
const HAND_CSS = ['#e60d0d', '#8c0dd9'];

function decodeBase64(s) {
  const bin = atob(s);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) out[i] = bin.charCodeAt(i);
  return out.buffer;
}

function parseGlb(loader, buffer) {
  return new Promise((resolve, reject) => loader.parse(buffer, '', resolve, reject));
}

function classify(root) {
  const parts = { left: [], right: [], object: null, top: null, bottom: null };
  root.traverse((o) => {
    if (o.isSkinnedMesh && o.name.startsWith('left')) parts.left.push(o);
    if (o.isSkinnedMesh && o.name.startsWith('right')) parts.right.push(o);
    if (o.name === 'object') parts.object = o;
    if (o.isMesh && o.name === 'object_top') parts.top = o;
    if (o.isMesh && o.name === 'object_bottom') parts.bottom = o;
  });
  return parts;
}

// Each vertex's neighbours (from the triangles), so that a contact colours its 1-ring.
function neighbours(geometry) {
  const n = geometry.attributes.position.count, idx = geometry.index.array;
  const ring = Array.from({ length: n }, () => new Set());
  for (let i = 0; i < idx.length; i += 3)
    for (let k = 0; k < 3; ++k) { ring[idx[i + k]].add(idx[i + (k + 1) % 3]); ring[idx[i + k]].add(idx[i + (k + 2) % 3]); }
  return ring.map((r) => Array.from(r));
}

function prepareContacts(part) {
  if (!part) return;
  part.userData.ring = neighbours(part.geometry);
  const n = part.geometry.attributes.position.count;
  part.geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * n).fill(1), 3));
  part.material = part.material.clone();
  part.material.vertexColors = true;
  part.material.needsUpdate = true;
}

// Scene markers of a sample's marks: per hand a sphere at the pinned wrist (shown at the
// pinned frames, through the hand), per region a wire sphere on its part (moves with it).
function makeMarkers(marks, parts, scene) {
  const pins = [0, 1].map((h) => {
    const m = new THREE.Mesh(new THREE.SphereGeometry(0.012, 16, 12),
      new THREE.MeshBasicMaterial({ color: HAND_CSS[h], transparent: true, opacity: 0.55, depthTest: false }));
    m.renderOrder = 10; m.visible = false; scene.add(m);
    return m;
  });
  const regions = [];
  for (const mk of marks) {
    if (!mk.region) continue;
    const part = mk.region.part === 'top' ? parts.top : parts.bottom;
    if (!part) continue;
    const m = new THREE.Mesh(new THREE.SphereGeometry(mk.region.radius, 20, 14),
      new THREE.MeshBasicMaterial({ color: HAND_CSS[mk.hand], wireframe: true, transparent: true, opacity: 0.6 }));
    m.position.set(...mk.region.point); m.visible = false; part.add(m);
    regions.push({ mark: mk, mesh: m });
  }
  return { pins, regions };
}

async function main() {
  const data = JSON.parse(document.getElementById('bimart-data').textContent);
  const canvas = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0.96, 0.96, 0.97);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x888899, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.8);
  sun.position.set(0.6, 1.5, 1.0);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(35, 1, 0.005, 50);
  const controls = new OrbitControls(camera, canvas);

  const loader = new GLTFLoader();
  const samples = [];
  for (const s of data.samples) {
    const gltf = await parseGlb(loader, decodeBase64(s.glb));
    const root = gltf.scene;
    const mixer = new THREE.AnimationMixer(root);
    for (const clip of gltf.animations) mixer.clipAction(clip).play();
    const parts = classify(root);
    if (s.contacts) { prepareContacts(parts.top); prepareContacts(parts.bottom); }
    root.visible = false;
    scene.add(root);
    samples.push({ info: s, root, mixer, parts, markers: makeMarkers(s.marks || [], parts, scene) });
  }

  const ui = {
    play: document.getElementById('play'), slider: document.getElementById('slider'),
    speed: document.getElementById('speed'), sample: document.getElementById('sample'),
    frame: document.getElementById('frame'), left: document.getElementById('show-left'),
    right: document.getElementById('show-right'), object: document.getElementById('show-object'),
    contacts: document.getElementById('show-contacts'), status: document.getElementById('status'),
    marks: document.getElementById('marks'), timeline: document.getElementById('timeline'),
    now: document.getElementById('now'),
  };
  samples.forEach((s, i) => ui.sample.add(new Option(s.info.name, String(i))));

  let current = 0, time = 0, playing = true, frame = -1, framesShown = 0;
  const cur = () => samples[current];
  const frames = () => cur().info.frames;
  const fps = () => cur().info.fps;
  // The clip's time of frame f. The clip lasts (frames - 1) / fps and loops, so the last
  // frame's own time would wrap to frame 0: it is taken a microsecond earlier.
  const clipTime = (f) => Math.min(f, frames() - 1) / fps() - (f >= frames() - 1 ? 1e-6 : 0);

  function applyContacts(s, f) {
    const c = s.info.contacts;
    if (!c || !s.parts.top || !s.parts.bottom) return;
    const top = s.parts.top.geometry.attributes.color, bottom = s.parts.bottom.geometry.attributes.color;
    top.array.fill(1); bottom.array.fill(1);
    if (ui.contacts.checked) {
      const hits = c.frames[f] || [];
      for (let i = 0; i + 1 < hits.length; i += 2) {
        const v = hits[i], col = CONTACT_COLORS[hits[i + 1]];
        const part = v < c.top ? s.parts.top : s.parts.bottom, k = v < c.top ? v : v - c.top;
        const attr = part.geometry.attributes.color;
        attr.setXYZ(k, col.r, col.g, col.b);
        for (const q of part.userData.ring[k]) attr.setXYZ(q, col.r, col.g, col.b);
      }
    }
    top.needsUpdate = true; bottom.needsUpdate = true;
  }

  // The marks at frame f: the line under the timeline, the pinned wrists, the regions.
  function applyMarks(s, f) {
    const marks = s.info.marks || [];
    const here = marks.filter((m) => f >= m.first && f <= m.last);
    ui.now.textContent = marks.length ? (here.length ? here.map((m) => m.label).join(' · ') : 'frame ' + f + ': free') : '';
    s.markers.pins.forEach((p) => { p.visible = false; });
    for (const m of here)
      if (m.wrists) { const p = s.markers.pins[m.hand]; p.position.set(...m.wrists[f - m.first]); p.visible = true; }
    for (const r of s.markers.regions) r.mesh.visible = f >= r.mark.first && f <= r.mark.last;
    drawTimeline(s, f);
  }

  // Two rows (left, right) over the frames; a redrawn stretch spans both; pins are ticks.
  function drawTimeline(s, f) {
    const marks = s.info.marks || [];
    if (!marks.length) return;
    const c = ui.timeline, dpr = window.devicePixelRatio || 1;
    const w = c.clientWidth, h = c.clientHeight;
    if (c.width !== Math.round(w * dpr)) { c.width = Math.round(w * dpr); c.height = Math.round(h * dpr); }
    const g = c.getContext('2d');
    g.setTransform(dpr, 0, 0, dpr, 0, 0);
    g.clearRect(0, 0, w, h);
    g.fillStyle = '#eee'; g.fillRect(0, 0, w, h);
    const n = frames(), x = (k) => (k / n) * w, row = h / 2;
    const order = ['contacts', 'redraw', 'top', 'bottom', 'any', 'none', 'wrist', 'pose'];
    for (const m of [...marks].sort((a, b) => order.indexOf(a.kind) - order.indexOf(b.kind))) {
      const pin = m.kind === 'wrist' || m.kind === 'pose';
      g.fillStyle = pin ? HAND_CSS[m.hand] : MARK_COLORS[m.kind];
      const x0 = x(m.first), x1 = Math.max(x(m.last + 1), x0 + (pin ? 3 : 1));
      if (m.hand < 0) g.fillRect(x0, 0, x1 - x0, h);
      else if (pin) g.fillRect(x0, m.hand * row, x1 - x0, row - 1);
      else g.fillRect(x0, m.hand * row + 1, x1 - x0, row - 3);
    }
    g.fillStyle = '#000'; g.fillRect(x(f + 0.5) - 1, 0, 2, h);
  }

  function setFrame(f) {
    const s = cur();
    f = Math.max(0, Math.min(frames() - 1, f));
    s.mixer.setTime(clipTime(f));
    if (f !== frame) { frame = f; framesShown += 1; applyContacts(s, f); applyMarks(s, f); }
    ui.slider.value = String(f);
    ui.frame.textContent = `frame ${f} / ${frames() - 1}`;
  }

  function visibility() {
    for (const s of samples) {
      s.root.visible = s === cur();
      if (s !== cur()) s.markers.pins.forEach((p) => { p.visible = false; });
      for (const m of s.parts.left) m.visible = ui.left.checked;
      for (const m of s.parts.right) m.visible = ui.right.checked;
      if (s.parts.object) s.parts.object.visible = ui.object.checked;
    }
  }

  // Frames the union of the scene's bounds at five moments of the sample.
  function frameCamera() {
    const s = cur();
    const box = new THREE.Box3();
    for (const u of [0, 0.25, 0.5, 0.75, 1]) {
      s.mixer.setTime(clipTime(u * (frames() - 1)));
      s.root.updateMatrixWorld(true);
      box.union(new THREE.Box3().setFromObject(s.root, true));
    }
    const centre = box.getCenter(new THREE.Vector3());
    const radius = Math.max(0.05, box.getSize(new THREE.Vector3()).length() / 2);
    const dist = 0.8 * radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));
    camera.position.copy(centre).add(new THREE.Vector3(0.35, 0.6, 1.0).normalize().multiplyScalar(dist));
    camera.near = dist / 100; camera.far = dist * 10; camera.updateProjectionMatrix();
    controls.target.copy(centre); controls.update();
    s.mixer.setTime(clipTime(Math.max(0, frame)));
  }

  function selectSample(i) {
    current = i;
    ui.slider.max = String(frames() - 1);
    visibility();
    frame = -1;
    setFrame(Math.min(Math.round(time * fps()), frames() - 1));
    ui.contacts.disabled = !cur().info.contacts;
    const directed = (cur().info.marks || []).length > 0;
    ui.marks.hidden = !directed;
    document.body.classList.toggle('directed', directed);
    if (directed) { ui.timeline.title = 'left hand above, right hand below: ' +
      'orange on the top part, blue on the bottom part, grey anywhere, dark off the object, ' +
      'red/purple ticks pinned wrists or poses, green the stretch drawn anew; click to go to a frame';
      applyMarks(cur(), frame); }
  }

  ui.play.addEventListener('click', () => { playing = !playing; ui.play.textContent = playing ? 'Pause' : 'Play'; });
  ui.slider.addEventListener('input', () => { time = Number(ui.slider.value) / fps(); setFrame(Number(ui.slider.value)); });
  ui.sample.addEventListener('change', () => selectSample(Number(ui.sample.value)));
  for (const box of [ui.left, ui.right, ui.object]) box.addEventListener('change', visibility);
  ui.contacts.addEventListener('change', () => applyContacts(cur(), frame));
  ui.timeline.addEventListener('click', (e) => {
    const f = Math.floor((e.offsetX / ui.timeline.clientWidth) * frames());
    playing = false; ui.play.textContent = 'Play'; time = f / fps(); setFrame(f);
  });

  function resize() {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) || canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
      renderer.setSize(w, h, false);
      camera.aspect = w / Math.max(1, h);
      camera.updateProjectionMatrix();
    }
  }

  selectSample(0);
  frameCamera();
  const clock = new THREE.Clock();
  renderer.setAnimationLoop(() => {
    const dt = Math.min(clock.getDelta(), 0.1);
    if (playing) {
      time += dt * Number(ui.speed.value);
      const length = frames() / fps();
      if (time >= length) time %= length;
      setFrame(Math.floor(time * fps() + 1e-6));
    }
    resize();
    controls.update();
    renderer.render(scene, camera);
  });

  // Flat colours per class (left, right, object) drawn once, counted, then the normal view
  // again: lets a test check what the picture shows.
  function coverage() {
    const flat = { left: new THREE.MeshBasicMaterial({ color: 0xff0000 }), right: new THREE.MeshBasicMaterial({ color: 0x00ff00 }),
                   object: new THREE.MeshBasicMaterial({ color: 0x0000ff }) };
    const saved = [];
    const s = cur();
    const swap = (m, mat) => { saved.push([m, m.material]); m.material = mat; };
    s.parts.left.forEach((m) => swap(m, flat.left));
    s.parts.right.forEach((m) => swap(m, flat.right));
    [s.parts.top, s.parts.bottom].forEach((m) => m && swap(m, flat.object));
    const bg = scene.background;
    scene.background = new THREE.Color(0, 0, 0);
    renderer.render(scene, camera);
    const gl = renderer.getContext();
    const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    const px = new Uint8Array(4 * w * h);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const count = { left: 0, right: 0, object: 0, pixels: w * h };
    for (let i = 0; i < px.length; i += 4) {
      const r = px[i], g = px[i + 1], b = px[i + 2];
      if (r > 200 && g < 50 && b < 50) count.left++;
      else if (g > 200 && r < 50 && b < 50) count.right++;
      else if (b > 200 && r < 50 && g < 50) count.object++;
    }
    for (const [m, mat] of saved) m.material = mat;
    scene.background = bg;
    renderer.render(scene, camera);
    return count;
  }

  window.bimartViewer = {
    ready: true, samples: samples.length, frame: () => frame, framesShown: () => framesShown,
    setFrame: (f) => { time = f / fps(); setFrame(f); }, play: (on) => { playing = on; }, coverage,
    select: (i) => { ui.sample.value = String(i); selectSample(i); },
    // What the marks show now: pinned wrists and regions visible, and the line of text.
    marksShown: () => ({ marks: (cur().info.marks || []).length, pins: cur().markers.pins.filter((p) => p.visible).length,
                         regions: cur().markers.regions.filter((r) => r.mesh.visible).length, text: ui.now.textContent }),
  };
  ui.status.textContent = '';
}

main().catch((e) => {
  document.getElementById('status').textContent = 'error: ' + e.message;
  console.error(e);
});
