// The viewer page's panel (viewer.js draws the 3-D view): tracking state, frame, timing, the
// current camera image with its keypoints, the loop closures. Written so that a streamed update
// costs little: the DOM is touched only where a text changed, and only the image of the frame
// shown is decoded, at the size it is shown.
'use strict';

const STATE_COLOURS = ['#777777', '#4cd964', '#4aa3ff', '#ff4d4d'];  // unmatched, matched, new, outlier
const ui = (id) => document.getElementById(id);

function setText(id, text) {  // the DOM is touched only for a change: no style or layout work else
  const element = ui(id);
  if (element.textContent !== text) element.textContent = text;
}

function showFrame(frame) {
  window.orbisScene.frames = Math.max(window.orbisScene.frames, frame.index + 1);
  setText('state', frame.state);
  const stateClass = 'n state-' + frame.state;
  if (ui('state').className !== stateClass) ui('state').className = stateClass;
  setText('frame', frame.index + (frame.newKeyFrame ? ' (new keyframe)' : ''));
  for (const name of ['extraction', 'tracking'])  // this frame's, and the median the server keeps
    setText('t-' + name, frame.ms[name].toFixed(1) + ' · ' + frame.ms[name + 'Median'].toFixed(1));
  drawImage(frame);
}

// The current image (a scaled-down JPEG; none from a run without images) under the keypoints,
// drawn at the size the canvas takes on the page. Decoding is asynchronous: a frame whose image
// arrives after a newer frame's is not drawn.
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
  // The canvas's size is read before any text is written: reading a size after a change to the
  // page forces the browser to lay the page out again at once (then again at the next drawing).
  const image = ui('image');
  const width = Math.max(1, Math.round(image.clientWidth || 320));
  const counts = [0, 0, 0, 0];
  for (let i = 2; i < frame.keypoints.length; i += 3) counts[frame.keypoints[i]]++;
  setText('matches', `${counts[1]} / ${counts[2]} / ${counts[3]}`);
  const height = frame.width > 0 ? Math.max(1, Math.round(width * frame.height / frame.width)) : image.height;
  if (image.width !== width || image.height !== height) {
    image.width = width;
    image.height = height;
  }
  const g = image.getContext('2d');
  if (img) {
    g.drawImage(img, 0, 0, width, height);
    window.orbisScene.images++;
  } else {
    g.fillStyle = '#05070a';
    g.fillRect(0, 0, width, height);
  }
  // As ORB-SLAM2's frame drawer: a box and a centre dot per keypoint; unmatched ones only dimly.
  const k = frame.keypoints;
  const s = frame.width > 0 ? width / frame.width : 1;
  const r = Math.max(2, width / 160);
  g.lineWidth = 1;
  for (let state = 0; state < 4; ++state) {  // one colour at a time: fewer state changes
    g.strokeStyle = g.fillStyle = STATE_COLOURS[state];
    g.globalAlpha = state === 0 ? 0.45 : 1;
    for (let i = 0; i < k.length; i += 3) {
      if (k[i + 2] !== state) continue;
      const x = k[i] * s, y = k[i + 1] * s;
      if (state !== 0) g.strokeRect(x - r, y - r, 2 * r, 2 * r);
      g.fillRect(x - 1, y - 1, 2, 2);
    }
  }
  g.globalAlpha = 1;
  showSceneState();
}

function showSceneState() { setText('scene-state', JSON.stringify(window.orbisScene)); }

let mergesAnnounced = 0;
function announceMerges(merges) {
  for (let i = mergesAnnounced; i < merges.length; ++i) {
    const m = merges[i];
    const item = document.createElement('li');
    item.textContent = `frame ${m.frame}: map ${m.moved} merged into map ${m.kept}, ${m.inliers} inliers`;
    ui('loops').appendChild(item);
    const banner = ui('banner');
    banner.textContent = `maps merged: map ${m.moved} into map ${m.kept}`;
    banner.style.display = 'block';
    setTimeout(() => { banner.style.display = 'none'; }, 4000);
  }
  mergesAnnounced = Math.max(mergesAnnounced, merges.length);
}

let loopsAnnounced = 0;
function announceLoops(closures) {
  for (let i = loopsAnnounced; i < closures.length; ++i) {
    const c = closures[i];
    const item = document.createElement('li');
    item.textContent = `frame ${c.frame}: keyframe ${c.current} ↔ ${c.loop}, ${c.inliers} inliers`;
    ui('loops').appendChild(item);
    const banner = ui('banner');
    banner.textContent = `loop closed: keyframe ${c.current} ↔ ${c.loop}`;
    banner.style.display = 'block';
    setTimeout(() => { banner.style.display = 'none'; }, 4000);
  }
  loopsAnnounced = Math.max(loopsAnnounced, closures.length);
}
