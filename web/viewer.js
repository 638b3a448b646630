// hapticd's live viewer: the running scene (asked with "scene"), the device pose (the held body
// ghosted) and the proxy (the held body solid), every contact point with its normal and depth,
// force and torque arrows, body poses as they move, a strip chart of tick time and force; arm,
// disarm, load a scene, and drag the probe with the mouse (pose messages). protocol/websocket.md.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { Connection } from './connection.js';
import { StripChart } from './chart.js';

const $ = (id) => document.getElementById(id);
const view = $('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
view.appendChild(renderer.domElement);
const world = new THREE.Scene();
world.background = new THREE.Color(0x2b2f36);
world.add(new THREE.HemisphereLight(0xffffff, 0x445566, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(1, 2, 1.5);
world.add(sun);
const camera = new THREE.PerspectiveCamera(45, 1, 0.001, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
const chart = new StripChart($('chart'));

// what the page shows, and what its test reads (window.hapticdViewer)
const v = {
  scene: null, // { root, bodies: Map index → Object3D, held, ghost, scale }
  sceneName: '',
  statesSeen: 0,
  lastState: null,
  armed: false,
  contactArrows: [],
  errors: [],
};
const forceArrow = new THREE.ArrowHelper(new THREE.Vector3(0, 1, 0), new THREE.Vector3(), 1, 0xffaa33);
const torqueArrow = new THREE.ArrowHelper(new THREE.Vector3(0, 1, 0), new THREE.Vector3(), 1, 0xcc66ff);
forceArrow.visible = torqueArrow.visible = false;
world.add(forceArrow, torqueArrow);

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();

function log(text) {
  $('log').textContent = `${new Date().toLocaleTimeString()} ${text}\n` + $('log').textContent.slice(0, 2000);
}

// an object's world pose set to p [x,y,z], q [x,y,z,w] under whatever parent it has
function setWorldPose(obj, p, q) {
  const m = new THREE.Matrix4().compose(new THREE.Vector3(...p), new THREE.Quaternion(...q),
                                        new THREE.Vector3(1, 1, 1));
  if (obj.parent) {
    obj.parent.updateMatrixWorld(true);
    m.premultiply(new THREE.Matrix4().copy(obj.parent.matrixWorld).invert());
  }
  const scale = obj.scale.clone();
  m.decompose(obj.position, obj.quaternion, new THREE.Vector3());
  obj.scale.copy(scale);
}

function ghostOf(obj) {
  const g = obj.clone(true);
  g.traverse((o) => {
    if (o.isMesh) {
      // seen through what it is pressed into: the device pose is often inside another body
      o.material = new THREE.MeshStandardMaterial({ color: 0x88ccff, transparent: true, opacity: 0.3,
                                                    depthWrite: false, depthTest: false });
    }
  });
  return g;
}

function showScene(m) {
  if (v.scene) world.remove(v.scene.root, v.scene.ghost);
  const bytes = Uint8Array.from(atob(m.glb_base64), (c) => c.charCodeAt(0));
  new GLTFLoader().parse(bytes.buffer, '', (gltf) => {
    const root = gltf.scene;
    const bodies = new Map();
    for (const b of m.bodies) {
      const node = root.getObjectByName(THREE.PropertyBinding.sanitizeNodeName(b.name));
      if (node) bodies.set(b.index, node);
    }
    const scale = m.length_scale || 1;
    let held = bodies.get(m.probe_body);
    if (!held) { // a probe sphere of the config
      held = new THREE.Mesh(new THREE.SphereGeometry(scale * 0.02),
                            new THREE.MeshStandardMaterial({ color: 0xdddddd }));
      root.add(held);
    }
    const ghost = ghostOf(held);
    world.add(root, ghost);
    v.scene = { root, bodies, held, ghost, scale, probe: m.probe_body };
    v.sceneName = m.name;
    const box = new THREE.Box3().setFromObject(root);
    const c = box.getCenter(new THREE.Vector3());
    const r = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-6);
    camera.position.copy(c).add(new THREE.Vector3(0.6 * r, 0.5 * r, 0.9 * r));
    camera.near = r / 1000;
    camera.far = r * 100;
    camera.updateProjectionMatrix();
    controls.target.copy(c);
    controls.update();
    log(`scene '${m.name}': ${m.bodies.length} bodies`);
  }, (err) => log(`scene '${m.name}' cannot be shown: ${err.message || err}`));
}

function arrowTo(arrow, origin, vec, lengthPerUnit, maxLength) {
  const n = Math.hypot(...vec);
  arrow.visible = n > 1e-9;
  if (!arrow.visible) return;
  const len = Math.min(n * lengthPerUnit, maxLength);
  arrow.position.set(...origin);
  arrow.setDirection(new THREE.Vector3(...vec).divideScalar(n));
  arrow.setLength(len, len * 0.25, len * 0.12);
}

function showContacts(contacts, scale) {
  while (v.contactArrows.length < contacts.length) {
    const a = new THREE.ArrowHelper(new THREE.Vector3(0, 1, 0), new THREE.Vector3(), 1, 0xff4444);
    const dot = new THREE.Mesh(new THREE.SphereGeometry(1), new THREE.MeshBasicMaterial({ color: 0xff4444 }));
    a.add(dot);
    // drawn over everything: contacts are where the bodies hide each other
    for (const part of [a.line, a.cone, dot]) { part.material.depthTest = false; part.renderOrder = 10; }
    world.add(a);
    v.contactArrows.push(a);
  }
  v.contactArrows.forEach((a, i) => {
    const c = contacts[i];
    a.visible = !!c;
    if (!c) return;
    // length: a base for visibility, plus the depth magnified 20 times
    const len = scale * 0.08 + 20 * Math.max(0, c.depth);
    a.position.set(...c.p);
    a.setDirection(new THREE.Vector3(...c.n).normalize());
    a.setLength(len, len * 0.2, len * 0.1);
    a.children[a.children.length - 1].scale.setScalar(scale * 0.008);
  });
}

function showState(s) {
  v.statesSeen += 1;
  v.lastState = s;
  v.armed = s.armed;
  const sc = v.scene;
  if (sc) {
    setWorldPose(sc.held, s.proxy.p, s.proxy.q);
    setWorldPose(sc.ghost, s.device.p, s.device.q);
    for (const b of s.bodies) {
      const node = sc.bodies.get(b.body);
      if (node && b.body !== sc.probe) setWorldPose(node, b.p, b.q);
    }
    showContacts(s.contacts, sc.scale);
    arrowTo(forceArrow, s.proxy.p, s.force, sc.scale * 0.03, sc.scale * 0.5);
    arrowTo(torqueArrow, s.proxy.p, s.torque, sc.scale * 0.3, sc.scale * 0.5);
  }
  const f = Math.hypot(...s.force);
  chart.push(s.tick_ns / 1000, f);
  const fmt = (a) => a.map((x) => x.toFixed(4)).join(', ');
  $('readout').textContent =
    `scene    ${v.sceneName}\ntick     ${s.tick}  t ${s.t.toFixed(3)} s\n` +
    `armed    ${s.armed}  streaming ${s.streaming}  faults ${s.faults.join(',') || 'none'}\n` +
    `device   ${fmt(s.device.p)}\nproxy    ${fmt(s.proxy.p)}\n` +
    `force    ${fmt(s.force)} N (|F| ${f.toFixed(3)})\ntorque   ${fmt(s.torque)} N·m\n` +
    `contacts ${s.contact_count}  max depth ${(s.max_penetration * 1000).toFixed(3)} mm\n` +
    s.contacts.slice(0, 6).map((c) => `  at ${fmt(c.p)} n ${fmt(c.n)} depth ${(c.depth * 1000).toFixed(3)} mm`).join('\n') +
    `\ntick     ${(s.tick_ns / 1000).toFixed(1)} µs (p99 ${(s.tick_p99_ns / 1000).toFixed(1)} µs)`;
}

const conn = new Connection((m) => {
  switch (m.type) {
    case 'welcome':
      $('link').textContent = `connected to ${location.host}` + (m.may_command ? '' : ' (watching only)');
      conn.send({ type: 'scene' });
      conn.send({ type: 'subscribe', rate_hz: 60 });
      break;
    case 'scene': showScene(m); break;
    case 'state': showState(m); break;
    case 'loaded':
      log(m.ok ? 'scene loaded' : `load refused: ${m.error}`);
      if (m.ok) conn.send({ type: 'scene' });
      break;
    case 'error': v.errors.push(m); log(`${m.ref}: ${m.error}`); break;
    default: break;
  }
}, (text) => { $('link').textContent = text; });
conn.open();

$('arm').onclick = () => conn.send({ type: 'arm' });
$('disarm').onclick = () => conn.send({ type: 'disarm' });
$('key').onchange = (e) => conn.setKey(e.target.value);
$('file').onchange = async (e) => {
  const file = e.target.files[0];
  if (!file) return;
  const bytes = new Uint8Array(await file.arrayBuffer());
  let bin = '';
  for (let i = 0; i < bytes.length; i += 0x8000) bin += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  conn.send({ type: 'load', name: file.name, glb_base64: btoa(bin) });
  log(`loading '${file.name}' (${bytes.length} bytes)`);
};

// drag the probe: while the button is held, the target follows the mouse on the plane through
// the device position that faces the camera, sent as pose messages at 100 Hz (after an arm)
const drag = { on: false, plane: new THREE.Plane(), target: null, timer: 0 };
function pointerTarget(ev) {
  const r = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((ev.clientX - r.left) / r.width) * 2 - 1, -((ev.clientY - r.top) / r.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, camera);
  const hit = new THREE.Vector3();
  return ray.ray.intersectPlane(drag.plane, hit) ? hit : null;
}
renderer.domElement.addEventListener('pointerdown', (ev) => {
  if (!$('drag').checked || !v.lastState) return;
  controls.enabled = false;
  drag.on = true;
  const p = new THREE.Vector3(...v.lastState.device.p);
  drag.plane.setFromNormalAndCoplanarPoint(camera.getWorldDirection(new THREE.Vector3()), p);
  drag.target = p;
  conn.send({ type: 'arm' });
  drag.timer = setInterval(() => {
    conn.send({ type: 'pose', p: drag.target.toArray(), q: v.lastState.device.q });
  }, 10);
});
renderer.domElement.addEventListener('pointermove', (ev) => {
  if (!drag.on) return;
  const t = pointerTarget(ev);
  if (t) drag.target = t;
});
window.addEventListener('pointerup', () => {
  if (!drag.on) return;
  drag.on = false;
  clearInterval(drag.timer);
  controls.enabled = true;
});

function frame() {
  requestAnimationFrame(frame);
  controls.update();
  chart.draw();
  renderer.render(world, camera);
}
frame();

// for the browser test (tests/web/viewer.test.mjs) and the curious
window.hapticdViewer = {
  get sceneName() { return v.sceneName; },
  get statesSeen() { return v.statesSeen; },
  get lastState() { return v.lastState; },
  get errors() { return v.errors; },
  meshCount() { let n = 0; v.scene?.root.traverse((o) => { if (o.isMesh) n += 1; }); return n; },
  heldPosition() { return v.scene ? v.scene.held.getWorldPosition(new THREE.Vector3()).toArray() : null; },
  visibleContactArrows() { return v.contactArrows.filter((a) => a.visible).length; },
  forceArrowVisible() { return forceArrow.visible; },
};
