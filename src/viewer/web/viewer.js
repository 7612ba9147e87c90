// The orbis live viewer: draws the map and the current frame that LiveViewer streams as
// server-sent events ("frame" and "map" messages, src/viewer/scene_json.hpp), with three.js.
// Coordinates arrive as orbis keeps them (x right, y down, z forward); the world group turns
// them to three.js's y-up. window.orbisScene holds the counts shown (images: camera images
// drawn), for tests.
'use strict';

const STATE_COLOURS = ['#777777', '#4cd964', '#4aa3ff', '#ff4d4d'];  // unmatched, matched, new, outlier
const LAYERS = {
  points: 'map points', keyFrames: 'keyframes', covisibility: 'covisibility', spanningTree: 'spanning tree',
  loops: 'loop edges', trajectory: 'trajectory', camera: 'current camera',
};

window.orbisScene = { keyframes: 0, points: 0, frames: 0, images: 0, loopClosures: 0, live: null, webgl: false };
const ui = (id) => document.getElementById(id);
const view = { paused: false, latestFrame: null, latestMap: null, fitted: false, frustumSize: 0.05,
               pointSize: 2, colouring: 'local', mode: 'follow', cameraCentre: null, loopsSeen: 0,
               userMoved: false };
const timings = { extraction: [], tracking: [] };

// ---- three.js scene ------------------------------------------------------------------------
const canvas = ui('scene');
let renderer = null;
try {
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  window.orbisScene.webgl = true;
} catch (e) {
  ui('legend').textContent = 'WebGL is not available: ' + e.message;
}
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x0e1117);
const world = new THREE.Group();
world.rotation.x = Math.PI;  // orbis y down, z forward -> three.js y up
scene.add(world);
const camera = new THREE.PerspectiveCamera(55, 1, 0.005, 500);
camera.position.set(0, 2, -3);
const controls = renderer ? new THREE.OrbitControls(camera, renderer.domElement) : null;
if (controls) {
  controls.addEventListener('change', () => requestRender());
  controls.addEventListener('start', () => { view.userMoved = true; });  // the user's drag or wheel only
}
const layers = {};
for (const name of Object.keys(LAYERS)) {
  layers[name] = new THREE.Group();
  world.add(layers[name]);
}

function replaceLayer(name, object) {
  const group = layers[name];
  for (const child of group.children) {
    child.geometry.dispose();
    child.material.dispose();
  }
  group.remove(...group.children);
  if (object) group.add(object);
}

function lineSegments(positions, colour, opacity = 1) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  const material = new THREE.LineBasicMaterial({ color: colour, transparent: opacity < 1, opacity });
  return new THREE.LineSegments(geometry, material);
}

// ---- geometry from orbis poses ---------------------------------------------------------------
// Twc: row-major 3x4 camera-to-world.
function transform(T, x, y, z) {
  return [T[0] * x + T[1] * y + T[2] * z + T[3], T[4] * x + T[5] * y + T[6] * z + T[7],
          T[8] * x + T[9] * y + T[10] * z + T[11]];
}

function pushFrustum(out, T, size) {
  const w = size, h = size * 0.75, z = size * 0.8;
  const apex = transform(T, 0, 0, 0);
  const corners = [[-w, -h], [w, -h], [w, h], [-w, h]].map(([x, y]) => transform(T, x, y, z));
  for (let i = 0; i < 4; ++i) out.push(...apex, ...corners[i], ...corners[i], ...corners[(i + 1) % 4]);
}

function pointColours(points, maxKeyFrame) {
  const colours = new Float32Array(points.length / 5 * 3);
  let anyLocal = false;  // a finished run's folder or a map file has no local map: colour by age
  for (let i = 4; i < points.length && !anyLocal; i += 5) anyLocal = points[i] === 1;
  const byLocalMap = view.colouring === 'local' && anyLocal;
  for (let i = 0, j = 0; i < points.length; i += 5, j += 3) {
    if (byLocalMap) {
      const local = points[i + 4] === 1;
      colours.set(local ? [1.0, 0.25, 0.25] : [0.75, 0.78, 0.85], j);
    } else {
      const age = maxKeyFrame > 0 ? points[i + 3] / maxKeyFrame : 1;  // 0 oldest, 1 newest
      colours.set([0.25 + 0.75 * age, 0.45 + 0.4 * age, 1.0 - 0.8 * age], j);
    }
  }
  return colours;
}

function drawPoints(map) {
  const positions = new Float32Array(map.points.length / 5 * 3);
  for (let i = 0, j = 0; i < map.points.length; i += 5, j += 3) positions.set(map.points.slice(i, i + 3), j);
  const maxKeyFrame = map.keyFrames.length ? map.keyFrames[map.keyFrames.length - 1].id : 0;
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(pointColours(map.points, maxKeyFrame), 3));
  const material = new THREE.PointsMaterial({ size: view.pointSize, sizeAttenuation: false, vertexColors: THREE.VertexColors });
  replaceLayer('points', new THREE.Points(geometry, material));
}

function drawKeyFrames(map) {
  const centres = new Map();
  const frusta = [];
  for (const k of map.keyFrames) {
    centres.set(k.id, [k.Twc[3], k.Twc[7], k.Twc[11]]);
    pushFrustum(frusta, k.Twc, view.frustumSize);
  }
  const covisibility = [], tree = [], loops = [];
  for (const k of map.keyFrames) {
    const a = centres.get(k.id);
    for (const c of k.covisibles) if (centres.has(c)) covisibility.push(...a, ...centres.get(c));
    if (centres.has(k.parent)) tree.push(...a, ...centres.get(k.parent));
    for (const l of k.loops) if (centres.has(l)) loops.push(...a, ...centres.get(l));
  }
  replaceLayer('keyFrames', lineSegments(frusta, 0x4aa3ff));
  replaceLayer('covisibility', lineSegments(covisibility, 0x3fbf7f, 0.35));
  replaceLayer('spanningTree', lineSegments(tree, 0xe0c060, 0.8));
  replaceLayer('loops', lineSegments(loops, 0xff40a0));
}

function drawTrajectory(map) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(map.trajectory, 3));
  replaceLayer('trajectory', new THREE.Line(geometry, new THREE.LineBasicMaterial({ color: 0x40d0e0 })));
}

function drawCurrentCamera(frame) {
  if (!frame.Twc) return;
  const frustum = [];
  pushFrustum(frustum, frame.Twc, view.frustumSize * 2);
  replaceLayer('camera', lineSegments(frustum, 0x50ff50));
  view.cameraCentre = new THREE.Vector3(frame.Twc[3], frame.Twc[7], frame.Twc[11]).applyMatrix4(world.matrixWorld);
}

// ---- camera modes ------------------------------------------------------------------------------
function mapBounds() {
  world.updateMatrixWorld();
  const box = new THREE.Box3().setFromObject(layers.keyFrames);
  box.union(new THREE.Box3().setFromObject(layers.trajectory));
  if (box.isEmpty()) box.setFromObject(layers.points);
  return box;
}

function fitView(top) {
  const box = mapBounds();
  if (box.isEmpty()) return;
  const centre = box.getCenter(new THREE.Vector3());
  const radius = Math.max(0.5, box.getSize(new THREE.Vector3()).length());
  controls.target.copy(centre);
  if (top) {
    camera.up.set(0, 0, -1);
    camera.position.set(centre.x, centre.y + radius * 1.3, centre.z + 0.001);
  } else {
    camera.up.set(0, 1, 0);
    camera.position.set(centre.x - radius * 0.6, centre.y + radius * 0.7, centre.z - radius * 0.9);
  }
  controls.update();
}

function followCamera() {
  if (view.mode !== 'follow' || !view.cameraCentre || !controls) return;
  const shift = view.cameraCentre.clone().sub(controls.target);
  controls.target.add(shift);
  camera.position.add(shift);
  controls.update();
}

function showSceneState() { ui('scene-state').textContent = JSON.stringify(window.orbisScene); }

// ---- panel ---------------------------------------------------------------------------------------
function median(values) {
  const s = [...values].sort((a, b) => a - b);
  return s.length ? s[Math.floor(s.length / 2)] : 0;
}

function showTiming(name, ms) {
  timings[name].push(ms);
  if (timings[name].length > 100) timings[name].shift();
  ui('t-' + name).textContent = ms.toFixed(1) + ' · ' + median(timings[name]).toFixed(1);
}

// The current image (a scaled-down JPEG; none from a run without images) under the keypoints,
// drawn in the full image's pixels. Decoding is asynchronous: a frame whose image arrives after
// a newer frame's is not drawn.
const picture = { frame: null };
function drawImage(frame) {
  picture.frame = frame;
  if (!frame.image) {
    paintImage(frame, null);
    return;
  }
  const img = new Image();
  img.onload = () => { if (picture.frame === frame) paintImage(frame, img); };
  img.src = 'data:image/jpeg;base64,' + frame.image;
}

function paintImage(frame, img) {  // the counts beside the picture are of the frame it shows
  const counts = [0, 0, 0, 0];
  for (let i = 2; i < frame.keypoints.length; i += 3) counts[frame.keypoints[i]]++;
  ui('matches').textContent = `${counts[1]} / ${counts[2]} / ${counts[3]}`;
  const image = ui('image');
  if (frame.width > 0 && (image.width !== frame.width || image.height !== frame.height)) {
    image.width = frame.width;
    image.height = frame.height;
  }
  const g = image.getContext('2d');
  if (img) {
    g.imageSmoothingEnabled = true;
    g.drawImage(img, 0, 0, image.width, image.height);
    window.orbisScene.images++;
    showSceneState();
  } else {
    g.fillStyle = '#05070a';
    g.fillRect(0, 0, image.width, image.height);
  }
  // As ORB-SLAM2's frame drawer: a box and a centre dot per keypoint; unmatched ones only dimly.
  const k = frame.keypoints;
  const r = Math.max(2, image.width / 160);
  g.lineWidth = Math.max(1, image.width / 400);
  for (let i = 0; i < k.length; i += 3) {
    const state = k[i + 2];
    g.strokeStyle = g.fillStyle = STATE_COLOURS[state];
    g.globalAlpha = state === 0 ? 0.45 : 1;
    if (state !== 0) g.strokeRect(k[i] - r, k[i + 1] - r, 2 * r, 2 * r);
    g.fillRect(k[i] - 1, k[i + 1] - 1, 2, 2);
  }
  g.globalAlpha = 1;
}

function applyFrame(frame) {
  window.orbisScene.frames = frame.index + 1;
  ui('state').textContent = frame.state;
  ui('state').className = 'n state-' + frame.state;
  ui('frame').textContent = frame.index + (frame.newKeyFrame ? ' (new keyframe)' : '');
  showTiming('extraction', frame.ms.extraction);
  showTiming('tracking', frame.ms.tracking);
  drawImage(frame);
  drawCurrentCamera(frame);
  followCamera();
  requestRender();
}

function announceLoops(closures) {
  for (let i = view.loopsSeen; i < closures.length; ++i) {
    const c = closures[i];
    const item = document.createElement('li');
    item.textContent = `frame ${c.frame}: keyframe ${c.current} ↔ ${c.loop}, ${c.inliers} inliers`;
    ui('loops').appendChild(item);
    const banner = ui('banner');
    banner.textContent = `loop closed: keyframe ${c.current} ↔ ${c.loop}`;
    banner.style.display = 'block';
    setTimeout(() => { banner.style.display = 'none'; }, 4000);
  }
  view.loopsSeen = closures.length;
}

function applyMap(map) {
  Object.assign(window.orbisScene, { keyframes: map.keyFrames.length, points: map.points.length / 5,
                                     loopClosures: map.loopClosures.length, live: map.live });
  window.orbisScene.frames = Math.max(window.orbisScene.frames, map.frames);
  if (map.trajectory.length >= 6) {  // frusta sized to the path: 2 % of its extent
    const box = new THREE.Box3().setFromArray(map.trajectory);
    view.frustumSize = Math.min(0.3, Math.max(0.02, box.getSize(new THREE.Vector3()).length() * 0.02));
  }
  drawPoints(map);
  drawKeyFrames(map);
  drawTrajectory(map);
  announceLoops(map.loopClosures);
  ui('mode').textContent = map.live ? '— live' : '— finished run';
  ui('counts').textContent = `${map.keyFrames.length} / ${map.points.length / 5}`;
  // The top view keeps the whole growing map in sight until the user moves the camera.
  if (controls && map.keyFrames.length && (!view.fitted || (view.mode === 'top' && !view.userMoved))) {
    fitView(view.mode === 'top');
    view.fitted = true;
  }
  showSceneState();
  requestRender();
}

// ---- controls and stream ---------------------------------------------------------------------------
function buildControls() {
  for (const [name, label] of Object.entries(LAYERS)) {
    const box = document.createElement('label');
    box.innerHTML = `<input type="checkbox" checked> ${label}`;
    box.firstChild.addEventListener('change', (e) => {
      layers[name].visible = e.target.checked;
      requestRender();
    });
    ui('layers').appendChild(box);
  }
  ui('camera-mode').addEventListener('change', (e) => {
    view.mode = e.target.value;
    view.userMoved = false;
    if (controls) fitView(view.mode === 'top');
  });
  ui('point-size').addEventListener('input', (e) => {
    view.pointSize = Number(e.target.value);
    for (const p of layers.points.children) p.material.size = view.pointSize;
    requestRender();
  });
  ui('colouring').addEventListener('change', (e) => {
    view.colouring = e.target.value;
    if (view.latestMap) drawPoints(view.latestMap);
    requestRender();
  });
  ui('pause').addEventListener('click', () => {
    view.paused = !view.paused;
    ui('pause').textContent = view.paused ? 'resume' : 'pause';
    if (!view.paused) {
      if (view.latestMap) applyMap(view.latestMap);
      if (view.latestFrame) applyFrame(view.latestFrame);
    }
  });
}

// ?view=follow|free|top in the address picks the camera mode at the start.
function applyQuery() {
  const mode = new URLSearchParams(location.search).get('view');
  if (['follow', 'free', 'top'].includes(mode)) {
    view.mode = mode;
    ui('camera-mode').value = mode;
  }
}

// The stream closes by itself once the run has finished (its map will not change), or, with
// ?maps=N in the address, after N map messages, or with ?loops=N after the map that shows the
// N-th loop closure: a headless browser takes its screenshot once no request is open.
function connect() {
  const query = new URLSearchParams(location.search);
  const closeAfterMaps = Number(query.get('maps')) || Infinity;
  const closeAfterLoops = Number(query.get('loops')) || Infinity;
  let maps = 0;
  const events = new EventSource('events');
  events.addEventListener('frame', (e) => {
    view.latestFrame = JSON.parse(e.data);
    if (!view.paused) applyFrame(view.latestFrame);
  });
  events.addEventListener('map', (e) => {
    view.latestMap = JSON.parse(e.data);
    if (!view.paused) applyMap(view.latestMap);
    if (!view.latestMap.live || ++maps >= closeAfterMaps || view.latestMap.loopClosures.length >= closeAfterLoops)
      events.close();
  });
  events.onerror = () => { ui('mode').textContent = '— disconnected (retrying)'; };
}

function resize() {  // true when the canvas changed size
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (!renderer || (canvas.width === w && canvas.height === h)) return false;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
  return true;
}

// Draws only when something changed (a message, the mouse, the window): a browser on the
// machine that runs SLAM then takes little CPU from it.
let needsRender = true;
function requestRender() { needsRender = true; }

function animate() {
  requestAnimationFrame(animate);
  if (resize()) needsRender = true;
  if (renderer && needsRender) {
    renderer.render(scene, camera);
    needsRender = false;
  }
}

buildControls();
applyQuery();
connect();
animate();
