// The orbis live viewer: draws the map and the current frame that LiveViewer streams as
// server-sent events ("frame" and "map" messages, src/viewer/scene_json.hpp and map_delta.hpp),
// with three.js; the map is kept by SceneStore (scene_store.js), the panel drawn by panel.js. Coordinates arrive as orbis keeps
// them (x right, y down, z forward); the world group turns them to three.js's y-up.
// window.orbisScene holds the counts shown (images: camera images drawn; fullMaps / mapDeltas:
// map messages of each kind applied), for tests.
//
// The browser often runs on the machine that runs SLAM, where every millisecond it spends is
// taken from tracking: streamed updates are drawn at a few hertz (the user's own camera moves at
// once), geometry is updated in place, materials and shaders are made once, only the frame that
// is shown has its image decoded, and a software WebGL (no GPU) draws without antialiasing.
'use strict';

// Streamed updates of the panel (state, counts, timing, camera image) and of the 3-D view, at most
// this many a second. Without a GPU every 3-D redraw costs CPU (about 15 ms of Chromium's GPU
// process with SwiftShader, measured): once a second then.
const PANEL_DRAWS_PER_SECOND = 5;
const SOFTWARE_SCENE_DRAWS_PER_SECOND = 1;
const LAYERS = {
  points: 'map points', keyFrames: 'keyframes', covisibility: 'covisibility', spanningTree: 'spanning tree',
  loops: 'loop edges', trajectory: 'trajectory', camera: 'current camera',
};

window.orbisScene = { keyframes: 0, points: 0, frames: 0, images: 0, loopClosures: 0, maps: 0, merges: 0, live: null,
                      webgl: false, fullMaps: 0, mapDeltas: 0, renders: 0 };
const store = new SceneStore();
const view = { paused: false, frame: null, frameText: null, frameShown: null, fitted: false, frustumSize: 0.05, colouring: 'local',
               mode: 'follow', cameraCentre: null, userMoved: false, recolour: false, pointKey: null };

// ---- three.js scene ------------------------------------------------------------------------
function softwareWebGl() {  // SwiftShader and the like: every pixel costs CPU
  try {
    const gl = document.createElement('canvas').getContext('webgl');
    const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
    const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
    const lose = gl && gl.getExtension('WEBGL_lose_context');
    if (lose) lose.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  } catch (e) {
    return false;
  }
}

const canvas = ui('scene');
const software = softwareWebGl();
let renderer = null;
try {
  renderer = new THREE.WebGLRenderer({ canvas, antialias: !software });
  renderer.setPixelRatio(1);  // CSS pixels: a high-DPI screen would multiply the pixels to fill
  window.orbisScene.webgl = true;
} catch (e) {
  ui('legend').textContent = 'WebGL is not available: ' + e.message;
}
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x0e1117);
const world = new THREE.Group();
world.rotation.x = Math.PI;  // orbis y down, z forward -> three.js y up
scene.add(world);
world.updateMatrixWorld();
const camera = new THREE.PerspectiveCamera(55, 1, 0.005, 500);
camera.position.set(0, 2, -3);
const controls = renderer ? new THREE.OrbitControls(camera, renderer.domElement) : null;
// The page's own camera moves (following the camera, fitting the map) are drawn by the draw that
// makes them: OrbitControls.update() announces them as a change, which must not draw again.
let movingCameraItself = false;
function moveCameraItself(move) {
  movingCameraItself = true;
  try {
    move();
    controls.update();
  } finally {
    movingCameraItself = false;
  }
}
if (controls) {
  controls.addEventListener('change', () => { if (!movingCameraItself) interactiveDraw(); });
  controls.addEventListener('start', () => { view.userMoved = true; });  // the user's drag or wheel only
}
const layers = {};
for (const name of Object.keys(LAYERS)) {
  layers[name] = new THREE.Group();
  world.add(layers[name]);
}

// A layer's lines, in one geometry refilled in place (grown when too small) with one material.
class Lines {
  constructor(layer, colour, opacity = 1, strip = false) {
    this.material = new THREE.LineBasicMaterial({ color: colour, transparent: opacity < 1, opacity });
    this.layer = layer;
    this.strip = strip;
    this.data = new Float32Array(0);
    this.n = 0;
    this.object = null;
  }
  begin() { this.n = 0; }
  vertex(x, y, z) {
    if (this.n + 3 > this.data.length) {
      const grown = new Float32Array(Math.max(3072, 2 * this.data.length));
      grown.set(this.data);
      this.data = grown;
    }
    this.data[this.n++] = x;
    this.data[this.n++] = y;
    this.data[this.n++] = z;
  }
  end() {
    if (!this.object || this.object.geometry.attributes.position.array !== this.data) {
      if (this.object) {
        this.object.geometry.dispose();
        this.layer.remove(this.object);
      }
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(this.data, 3).setUsage(THREE.DynamicDrawUsage));
      this.object = this.strip ? new THREE.Line(geometry, this.material) : new THREE.LineSegments(geometry, this.material);
      this.object.frustumCulled = false;  // its bounds change with every update
      this.layer.add(this.object);
    }
    this.object.geometry.attributes.position.needsUpdate = true;
    this.object.geometry.setDrawRange(0, this.n / 3);
  }
}

// The atlas: each map its own colour (keyframes, and points outside the local map).
const mapPalette = [0x4aa3ff, 0xff9f40, 0x9d6bff, 0x50d070, 0xff5f7a, 0xd0d040, 0x40d0d0, 0xc08060];
const mapColour = (map) => new THREE.Color(mapPalette[map % mapPalette.length]);
const mapKeyFrameLines = new Map();  // map id -> Lines (map 0 draws into lines.keyFrames)
function keyFrameLinesOf(map) {
  if (map === 0) return lines.keyFrames;
  if (!mapKeyFrameLines.has(map)) mapKeyFrameLines.set(map, new Lines(layers.keyFrames, mapPalette[map % mapPalette.length]));
  return mapKeyFrameLines.get(map);
}

const lines = {
  keyFrames: new Lines(layers.keyFrames, 0x4aa3ff), covisibility: new Lines(layers.covisibility, 0x3fbf7f, 0.35),
  spanningTree: new Lines(layers.spanningTree, 0xe0c060, 0.8), loops: new Lines(layers.loops, 0xff40a0),
  trajectory: new Lines(layers.trajectory, 0x40d0e0), camera: new Lines(layers.camera, 0x50ff50),
};
const pointMaterial = new THREE.PointsMaterial({ size: 2, sizeAttenuation: false, vertexColors: THREE.VertexColors });
const pointCloud = { object: null, colours: new Float32Array(0) };

// ---- geometry from orbis poses ---------------------------------------------------------------
// Twc: row-major 3x4 camera-to-world.
function transform(T, x, y, z) {
  return [T[0] * x + T[1] * y + T[2] * z + T[3], T[4] * x + T[5] * y + T[6] * z + T[7],
          T[8] * x + T[9] * y + T[10] * z + T[11]];
}

function addFrustum(out, T, size) {
  const w = size, h = size * 0.75, z = size * 0.8;
  const apex = transform(T, 0, 0, 0);
  const corners = [[-w, -h], [w, -h], [w, h], [-w, h]].map(([x, y]) => transform(T, x, y, z));
  for (let i = 0; i < 4; ++i) {
    out.vertex(...apex);
    out.vertex(...corners[i]);
    out.vertex(...corners[i]);
    out.vertex(...corners[(i + 1) % 4]);
  }
}

function drawPoints() {
  if (store.grown || !pointCloud.object) {
    if (pointCloud.object) {
      pointCloud.object.geometry.dispose();
      layers.points.remove(pointCloud.object);
    }
    pointCloud.colours = new Float32Array(store.capacity * 3);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(store.positions, 3).setUsage(THREE.DynamicDrawUsage));
    geometry.setAttribute('color', new THREE.BufferAttribute(pointCloud.colours, 3).setUsage(THREE.DynamicDrawUsage));
    pointCloud.object = new THREE.Points(geometry, pointMaterial);
    pointCloud.object.frustumCulled = false;
    layers.points.add(pointCloud.object);
    store.grown = false;
  }
  colourPoints();
  const geometry = pointCloud.object.geometry;
  for (const attribute of [geometry.attributes.position, geometry.attributes.color]) {
    attribute.updateRange = { offset: 0, count: 3 * store.count };  // not the spare capacity
    attribute.needsUpdate = true;
  }
  geometry.setDrawRange(0, store.count);
}

// Red: the tracker's local map; grey: the rest. A finished run's folder or a map file has no
// local map: by age then, blue old to yellow new.
function colourPoints() {
  const c = pointCloud.colours, local = store.local, n = store.count;
  const byLocalMap = view.colouring === 'local' && local.subarray(0, n).includes(1);
  const byMap = view.colouring === 'map' || (byLocalMap && store.mapCount() > 1);
  showPointKey(byLocalMap, byMap ? store.mapIds() : []);
  const newest = store.newestKeyFrame();
  const colours = new Map();
  const colourOf = (firstKeyFrame) => {
    const map = store.mapOfKeyFrame(firstKeyFrame);
    if (!colours.has(map)) colours.set(map, mapColour(map).lerp(new THREE.Color(0xffffff), 0.25));
    return colours.get(map);
  };
  for (let i = 0; i < n; ++i) {
    if (byLocalMap && local[i] === 1) {
      c[3 * i] = 1.0;
      c[3 * i + 1] = 0.25;
      c[3 * i + 2] = 0.25;
    } else if (byMap) {
      const m = colourOf(store.firstKeyFrame[i]);
      c[3 * i] = m.r;
      c[3 * i + 1] = m.g;
      c[3 * i + 2] = m.b;
    } else if (byLocalMap) {
      c[3 * i] = 0.75;
      c[3 * i + 1] = 0.78;
      c[3 * i + 2] = 0.85;
    } else {
      const age = newest > 0 ? store.firstKeyFrame[i] / newest : 1;  // 0 oldest, 1 newest
      c[3 * i] = 0.25 + 0.75 * age;
      c[3 * i + 1] = 0.45 + 0.4 * age;
      c[3 * i + 2] = 1.0 - 0.8 * age;
    }
  }
}

function drawKeyFrames() {
  const { keyFrames, covisibility, spanningTree, loops } = lines;
  const mapLines = () => [...mapKeyFrameLines.values()];
  for (const l of [keyFrames, covisibility, spanningTree, loops, ...mapLines()]) l.begin();
  const centre = (k) => [k.Twc[3], k.Twc[7], k.Twc[11]];
  for (const k of store.keyFrames.values()) {
    const frusta = keyFrameLinesOf(k.map || 0);
    addFrustum(frusta, k.Twc, view.frustumSize);
    const edge = (out, other) => {
      if (!other) return;
      out.vertex(...centre(k));
      out.vertex(...centre(other));
    };
    for (const c of k.covisibles) edge(covisibility, store.keyFrames.get(c));
    edge(spanningTree, store.keyFrames.get(k.parent));
    for (const l of k.loops) edge(loops, store.keyFrames.get(l));
  }
  for (const l of [keyFrames, covisibility, spanningTree, loops, ...mapLines()]) l.end();
}

// Consecutive tracked cameras joined, except across a jump: a new map of the atlas starts in a
// frame of its own (until it is merged), and nothing was tracked across a loss, so a step longer
// than this many times the median step is left open rather than drawn as a straight line.
const TRAJECTORY_JUMP_STEPS = 20;

function drawTrajectory() {
  const t = store.trajectory;
  const step = (i) => Math.hypot(t[i + 3] - t[i], t[i + 4] - t[i + 1], t[i + 5] - t[i + 2]);
  const steps = [];
  for (let i = 0; i + 5 < t.length; i += 3) steps.push(step(i));
  const median = steps.length ? [...steps].sort((a, b) => a - b)[steps.length >> 1] : 0;
  lines.trajectory.begin();
  for (let i = 0, k = 0; i + 5 < t.length; i += 3, ++k) {
    if (steps[k] > TRAJECTORY_JUMP_STEPS * median) continue;
    lines.trajectory.vertex(t[i], t[i + 1], t[i + 2]);
    lines.trajectory.vertex(t[i + 3], t[i + 4], t[i + 5]);
  }
  lines.trajectory.end();
}

function drawCurrentCamera(frame) {
  if (!frame || !frame.Twc) return;
  lines.camera.begin();
  addFrustum(lines.camera, frame.Twc, view.frustumSize * 2);
  lines.camera.end();
  view.cameraCentre = new THREE.Vector3(frame.Twc[3], frame.Twc[7], frame.Twc[11]).applyMatrix4(world.matrixWorld);
}

// ---- camera modes ------------------------------------------------------------------------------
function mapBounds() {  // in three.js's world: keyframes and trajectory, or the points without them
  const box = new THREE.Box3();
  const add = (x, y, z) => box.expandByPoint(new THREE.Vector3(x, -y, -z));  // the world group's turn
  for (const k of store.keyFrames.values()) add(k.Twc[3], k.Twc[7], k.Twc[11]);
  const t = store.trajectory;
  for (let i = 0; i + 2 < t.length; i += 3) add(t[i], t[i + 1], t[i + 2]);
  const p = store.positions;
  if (box.isEmpty()) for (let i = 0; i < store.count; ++i) add(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
  return box;
}

function fitView(top) {
  const box = mapBounds();
  if (box.isEmpty()) return;
  const centre = box.getCenter(new THREE.Vector3());
  const radius = Math.max(0.5, box.getSize(new THREE.Vector3()).length());
  moveCameraItself(() => {
    controls.target.copy(centre);
    if (top) {
      camera.up.set(0, 0, -1);
      camera.position.set(centre.x, centre.y + radius * 1.3, centre.z + 0.001);
    } else {
      camera.up.set(0, 1, 0);
      camera.position.set(centre.x - radius * 0.6, centre.y + radius * 0.7, centre.z - radius * 0.9);
    }
  });
}

function followCamera() {
  if (view.mode !== 'follow' || !view.cameraCentre || !controls) return;
  const shift = view.cameraCentre.clone().sub(controls.target);
  moveCameraItself(() => {
    controls.target.add(shift);
    camera.position.add(shift);
  });
}

// ---- drawing -----------------------------------------------------------------------------------
// Brings the scene and the panel up to date with what has arrived, then renders.
function drawMap() {
  const t = store.trajectory;
  if (store.trajectoryChanged && t.length >= 6) {  // frusta sized to the path: 2 % of its extent
    const size = new THREE.Box3().setFromArray(t).getSize(new THREE.Vector3()).length();
    const frustumSize = Math.min(0.3, Math.max(0.02, size * 0.02));
    if (frustumSize !== view.frustumSize) store.keyFramesChanged = true;
    view.frustumSize = frustumSize;
  }
  if (store.pointsChanged || store.keyFramesChanged || view.recolour) drawPoints();  // age colours follow keyframes
  if (store.keyFramesChanged) drawKeyFrames();
  if (store.trajectoryChanged) drawTrajectory();
  const keyFramesChanged = store.keyFramesChanged;
  store.pointsChanged = store.keyFramesChanged = store.trajectoryChanged = view.recolour = false;
  Object.assign(window.orbisScene, { keyframes: store.keyFrames.size, points: store.count,
                                     loopClosures: store.loopClosures.length, maps: store.mapCount(),
                                     merges: store.merges.length, live: store.live });
  window.orbisScene.frames = Math.max(window.orbisScene.frames, store.frames);
  announceLoops(store.loopClosures);
  announceMerges(store.merges);
  setText('mode', store.live === null ? 'connecting…' : store.live ? '— live' : '— finished run');
  setText('counts', `${store.keyFrames.size} / ${store.count}`);
  // The top view keeps the whole growing map in sight until the user moves the camera.
  if (controls && keyFramesChanged && store.keyFrames.size &&
      (!view.fitted || (view.mode === 'top' && !view.userMoved))) {
    fitView(view.mode === 'top');
    view.fitted = true;
  }
  showSceneState();
}

// Interaction (the camera, a layer, the window) draws at the next animation frame; streamed
// updates wait until their part's period has passed since it was last drawn.
const drawing = {
  pending: false, timer: null, interactive: false,
  panel: { due: false, last: -Infinity, period: 1000 / PANEL_DRAWS_PER_SECOND },
  view3d: { due: false, last: -Infinity,
            period: 1000 / (software ? SOFTWARE_SCENE_DRAWS_PER_SECOND : PANEL_DRAWS_PER_SECOND) },
};

// The newest frame message is parsed when it is drawn, not when it arrives: a page in a hidden
// tab (the browser stops its drawing) then spends nothing on the frames it is sent.
function newestFrame() {
  if (view.frameText !== null) {
    view.frame = JSON.parse(view.frameText);
    view.frameText = null;
  }
  return view.frame;
}

function draw() {
  drawing.pending = false;
  newestFrame();
  const now = performance.now();
  const { panel, view3d } = drawing;
  let render = drawing.interactive;
  drawing.interactive = false;
  if (!view.paused && panel.due && now - panel.last >= panel.period) {
    panel.due = false;
    panel.last = now;
    if (view.frame && view.frame !== view.frameShown) {
      view.frameShown = view.frame;
      showFrame(view.frame);
    }
  }
  if (!view.paused && view3d.due && (render || now - view3d.last >= view3d.period)) {
    view3d.due = false;
    view3d.last = now;
    drawMap();
    drawCurrentCamera(view.frame);
    followCamera();
    render = true;
  }
  if (renderer && render) {
    renderer.render(scene, camera);
    window.orbisScene.renders++;
  }
  scheduleStreamed();
}

function requestDraw() {
  if (drawing.pending) return;
  drawing.pending = true;
  requestAnimationFrame(draw);
}

function interactiveDraw() {  // at once: the user moved the camera, resized, toggled a layer
  drawing.interactive = true;
  requestDraw();
}

function scheduleStreamed() {
  if (view.paused || drawing.pending || drawing.timer !== null) return;
  let at = Infinity;
  for (const part of [drawing.panel, drawing.view3d]) if (part.due) at = Math.min(at, part.last + part.period);
  if (at === Infinity) return;
  drawing.timer = setTimeout(() => {
    drawing.timer = null;
    requestDraw();
  }, Math.max(0, at - performance.now()));
}

function streamed(panel, view3d) {  // what a message changed
  drawing.panel.due ||= panel;
  drawing.view3d.due ||= view3d;
  scheduleStreamed();
}

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (!renderer || (canvas.width === w && canvas.height === h)) return;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
  interactiveDraw();
}

// ---- controls and stream ---------------------------------------------------------------------------
function buildControls() {
  for (const [name, label] of Object.entries(LAYERS)) {
    const box = document.createElement('label');
    // Each line layer's label in its colour: the 3-D view has no other key.
    const colour = lines[name] ? lines[name].material.color.getStyle() : null;
    box.innerHTML = `<input type="checkbox" checked> ` +
                    (colour ? `<span class="dot" style="background:${colour};margin-left:0"></span>` : '') + label;
    box.firstChild.addEventListener('change', (e) => {
      layers[name].visible = e.target.checked;
      interactiveDraw();
    });
    ui('layers').appendChild(box);
  }
  ui('camera-mode').addEventListener('change', (e) => {
    view.mode = e.target.value;
    view.userMoved = false;
    if (controls) fitView(view.mode === 'top');
    interactiveDraw();
  });
  ui('point-size').addEventListener('input', (e) => {
    pointMaterial.size = Number(e.target.value);
    interactiveDraw();
  });
  ui('colouring').addEventListener('change', (e) => {
    view.colouring = e.target.value;
    view.recolour = true;
    drawing.view3d.due = true;
    interactiveDraw();
  });
  ui('pause').addEventListener('click', () => {  // the stream goes on into the store, unseen
    view.paused = !view.paused;
    ui('pause').textContent = view.paused ? 'resume' : 'pause';
    if (!view.paused) scheduleStreamed();
  });
  if (window.ResizeObserver) new ResizeObserver(resize).observe(canvas);
  else window.addEventListener('resize', resize);
}

// The points' colours as colourPoints chose them, beside the choice of colouring.
// The key under the colouring menu: local map and the rest, each map's colour, or the age ramp.
function showPointKey(byLocalMap, maps = []) {
  const key = `${byLocalMap}:${maps.join(',')}`;
  if (key === view.pointKey) return;
  view.pointKey = key;
  const dot = (colour, label) => `<span class="dot" style="background:${colour}"></span>${label}`;
  const local = byLocalMap ? dot('#ff4040', 'local map') : '';
  if (maps.length) {
    ui('point-key').innerHTML = local + maps.map((m) => dot(
      '#' + mapColour(m).lerp(new THREE.Color(0xffffff), 0.25).getHexString(), `map ${m}`)).join('');
  } else {
    ui('point-key').innerHTML = byLocalMap ? local + dot('#bfc7d9', 'other')
      : dot('#4073ff', 'oldest keyframe') + dot('#ffd933', 'newest');
  }
}

// ?view=follow|free|top in the address picks the camera mode at the start.
function applyQuery() {
  const mode = new URLSearchParams(location.search).get('view');
  if (['follow', 'free', 'top'].includes(mode)) {
    view.mode = mode;
    ui('camera-mode').value = mode;
  }
}

// Each connection starts from an empty scene: the server sends the whole map or every change.
// The stream closes by itself once the run has finished (its map will not change), or, with
// ?maps=N in the address, after N map messages, or with ?loops=N (?merges=N) after the map that
// shows the N-th loop closure (merge of two maps of the atlas): a headless browser takes its
// screenshot once no request is open.
function connect() {
  const query = new URLSearchParams(location.search);
  const closeAfterMaps = Number(query.get('maps')) || Infinity;
  const closeAfterLoops = Number(query.get('loops')) || Infinity;
  const closeAfterMerges = Number(query.get('merges')) || Infinity;
  let maps = 0;
  const events = new EventSource('events');
  events.onopen = () => store.reset();
  events.addEventListener('frame', (e) => {
    view.frameText = e.data;
    streamed(true, true);  // the panel, and the current camera in 3-D
  });
  events.addEventListener('map', (e) => {
    const message = JSON.parse(e.data);
    if (!store.apply(message)) {  // a change missed: start again from the whole map
      events.close();
      connect();
      return;
    }
    window.orbisScene[message.full ? 'fullMaps' : 'mapDeltas']++;
    streamed(false, true);
    if (!store.live || ++maps >= closeAfterMaps || store.loopClosures.length >= closeAfterLoops ||
        store.merges.length >= closeAfterMerges) {
      events.close();
    }
  });
  events.onerror = () => setText('mode', '— disconnected (retrying)');
}

buildControls();
showPointKey(true);
applyQuery();
resize();
connect();
interactiveDraw();
