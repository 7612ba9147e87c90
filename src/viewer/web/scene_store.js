// The map as the page holds it, kept up to date from LiveViewer's map messages: whole maps
// ("full") and changes since the previous message (src/viewer/map_delta.hpp). Points live in
// typed arrays that three.js draws from directly (slots 0..count-1; a removed point's slot is
// filled by the last one), so a message that moves a few hundred points touches only those,
// and nothing is re-allocated unless the map outgrows the arrays.
'use strict';

class SceneStore {
  constructor() {
    this.reset();
  }

  reset() {
    this.seq = 0;  // the last message applied; 0: none, the scene is empty
    this.capacity = 0;
    this.count = 0;
    this.positions = new Float32Array(0);  // x, y, z per slot
    this.firstKeyFrame = new Float64Array(0);
    this.local = new Uint8Array(0);
    this.ids = [];                 // slot -> point id
    this.slotOf = new Map();       // point id -> slot
    this.keyFrames = new Map();    // id -> {id, frame, parent, Twc, covisibles, loops}
    this.trajectory = [];          // x, y, z per camera
    this.loopClosures = [];
    this.merges = [];
    this.live = null;
    this.frames = 0;
    this.grown = true;            // the arrays were replaced: geometry must be made anew
    this.pointsChanged = this.keyFramesChanged = this.trajectoryChanged = true;
  }

  // Applies one map message; false when it does not follow the last one (a gap: reconnect).
  apply(message) {
    if (message.full) this.reset();
    else if (message.seq !== this.seq + 1) return false;
    this.seq = message.seq;
    this.live = message.live;
    this.frames = message.frames;
    this.loopClosures = message.loopClosures;
    this.merges = message.merges || [];
    for (const id of message.removedKeyFrames) this.keyFrames.delete(id);
    for (const k of message.keyFrames) this.keyFrames.set(k.id, k);
    for (const id of message.removedPoints) this.removePoint(id);
    const p = message.points;
    this.reserve(this.count + p.length / 6);
    for (let i = 0; i < p.length; i += 6) this.setPoint(p[i], p[i + 1], p[i + 2], p[i + 3], p[i + 4], p[i + 5]);
    const trajectoryBefore = this.trajectory.length;
    this.trajectory.length = 3 * message.trajectoryFrom;
    for (const v of message.trajectory) this.trajectory.push(v);
    this.pointsChanged ||= p.length > 0 || message.removedPoints.length > 0;
    this.keyFramesChanged ||= message.keyFrames.length > 0 || message.removedKeyFrames.length > 0;
    this.trajectoryChanged ||= message.trajectory.length > 0 || this.trajectory.length !== trajectoryBefore;
    return true;
  }

  reserve(count) {
    if (count <= this.capacity) return;
    const capacity = Math.max(1024, 2 * count);
    const grow = (Type, old, width) => {
      const a = new Type(capacity * width);
      a.set(old.subarray(0, this.count * width));
      return a;
    };
    this.positions = grow(Float32Array, this.positions, 3);
    this.firstKeyFrame = grow(Float64Array, this.firstKeyFrame, 1);
    this.local = grow(Uint8Array, this.local, 1);
    this.capacity = capacity;
    this.grown = true;
  }

  setPoint(id, x, y, z, firstKeyFrame, local) {
    let slot = this.slotOf.get(id);
    if (slot === undefined) {
      slot = this.count++;
      this.slotOf.set(id, slot);
      this.ids[slot] = id;
    }
    this.positions[3 * slot] = x;
    this.positions[3 * slot + 1] = y;
    this.positions[3 * slot + 2] = z;
    this.firstKeyFrame[slot] = firstKeyFrame;
    this.local[slot] = local;
  }

  removePoint(id) {
    const slot = this.slotOf.get(id);
    if (slot === undefined) return;
    const last = --this.count;
    if (slot !== last) {  // the last point moves into the hole
      this.positions.copyWithin(3 * slot, 3 * last, 3 * last + 3);
      this.firstKeyFrame[slot] = this.firstKeyFrame[last];
      this.local[slot] = this.local[last];
      this.ids[slot] = this.ids[last];
      this.slotOf.set(this.ids[slot], slot);
    }
    this.ids.length = last;
    this.slotOf.delete(id);
  }

  // The atlas: the map of keyframe `id`, or of the nearest older keyframe still held (a point's
  // first keyframe may have been culled; keyframes of one map are made in a run of ids).
  mapOfKeyFrame(id) {
    const k = this.keyFrames.get(id);
    if (k) return k.map || 0;
    let best = -1, map = 0;
    for (const [other, kf] of this.keyFrames) if (other < id && other > best) { best = other; map = kf.map || 0; }
    return map;
  }

  mapCount() {
    return this.mapIds().length;
  }

  // The ids of the maps that hold keyframes, ascending.
  mapIds() {
    const maps = new Set();
    for (const k of this.keyFrames.values()) maps.add(k.map || 0);
    return [...maps].sort((a, b) => a - b);
  }

  newestKeyFrame() {
    let newest = 0;
    for (const id of this.keyFrames.keys()) newest = Math.max(newest, id);
    return newest;
  }
}
