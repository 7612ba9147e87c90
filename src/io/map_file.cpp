#include "orbis/io/map_file.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "orbis/bow/vocabulary_file.hpp"
#include "orbis/util/atomic_file.hpp"
#include "orbis/util/error.hpp"

namespace orbis {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'O', 'R', 'B', 'I', 'S', 'M', 'A', 'P'};
constexpr std::size_t kHeaderBytesVersion1 = 8 + 4 + 4 + 8 + 8 + 10 * 8 + 8 + 8;
constexpr std::uint32_t kFirstVersionWithScale = 2;
constexpr std::uint32_t kFirstVersionWithAtlas = 3;
constexpr std::uint8_t kRootFlag = 1, kGaugeFlag = 2;
constexpr std::size_t kTrailerBytes = 8;
constexpr std::size_t kDeclaredSizeOffset = 16;  // after magic, version and sensor

// Plain records for the arrays (std::pair is not trivially copyable); none has padding.
struct NodeFeature {
  bow::NodeId node;
  std::uint32_t feature;
};
struct Edge {
  std::uint64_t keyFrame;
  std::int64_t weight;
};
struct Observation {
  std::uint64_t keyFrame, index;
};

class Writer {
 public:
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  template <class T>
  void putArray(const std::vector<T>& values) {
    put<std::uint64_t>(values.size());
    for (const T& v : values) put(v);
  }
  void putIntrinsics(const MapIntrinsics& k) {
    for (double v : {k.fx, k.fy, k.cx, k.cy, k.bf, k.closeDepth, k.minX, k.maxX, k.minY, k.maxY}) put(v);
  }
  void putPose(const SE3d& T) {
    const Eigen::Quaterniond& q = T.so3().unitQuaternion();
    for (double v : {q.x(), q.y(), q.z(), q.w()}) put(v);
    for (int i = 0; i < 3; ++i) put(T.translation()(i));
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  std::vector<char> bytes_;
};

class Reader {
 public:
  Reader(const std::vector<char>& bytes, std::size_t end, const std::string& file)
      : bytes_(bytes), end_(end), file_(file) {}

  template <class T>
  T get(const char* what) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (end_ - pos_ < sizeof(T)) fail(std::string("ends inside ") + what);
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  // A count of elements of `elementBytes` each that must still fit in the file.
  std::size_t count(std::size_t elementBytes, const char* what) {
    const auto n = get<std::uint64_t>(what);
    if (elementBytes > 0 && n > (end_ - pos_) / elementBytes) fail(std::string("impossible count in ") + what);
    return static_cast<std::size_t>(n);
  }
  template <class T>
  std::vector<T> getArray(const char* what) {
    std::vector<T> out(count(sizeof(T), what));
    for (T& v : out) v = get<T>(what);
    return out;
  }
  MapIntrinsics getIntrinsics(const char* what) {
    MapIntrinsics k;
    for (double* v : {&k.fx, &k.fy, &k.cx, &k.cy, &k.bf, &k.closeDepth, &k.minX, &k.maxX, &k.minY, &k.maxY})
      *v = get<double>(what);
    return k;
  }
  SE3d getPose(const char* what) {
    double q[4], t[3];
    for (double& v : q) v = get<double>(what);
    for (double& v : t) v = get<double>(what);
    const Eigen::Quaterniond quaternion(q[3], q[0], q[1], q[2]);
    if (!(std::abs(quaternion.norm() - 1.0) < 1e-6)) fail(std::string("non-unit rotation in ") + what);
    for (double v : t)
      if (!std::isfinite(v)) fail(std::string("non-finite translation in ") + what);
    return SE3d(quaternion, Eigen::Vector3d(t[0], t[1], t[2]));
  }
  std::size_t position() const { return pos_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw fileError(file_, "corrupt map file at byte " + std::to_string(pos_) + ": " + what);
  }

 private:
  const std::vector<char>& bytes_;
  std::size_t end_;
  std::size_t pos_ = 0;
  std::string file_;
};

void writeFeatures(Writer& w, const FrameFeatures& f) {
  w.putArray(f.keypoints);
  w.putArray(f.keypointsUn);
  w.putArray(f.descriptors);
  w.putArray(f.uRight);
  w.putArray(f.depth);
  w.put(f.closeDepth);
  w.putArray(f.scales.scale);
  w.putArray(f.scales.invScale);
  w.putArray(f.scales.sigma2);
  w.putArray(f.scales.invSigma2);
  for (float v : {f.grid.minX(), f.grid.maxX(), f.grid.minY(), f.grid.maxY()}) w.put(v);
}

std::shared_ptr<const FrameFeatures> readFeatures(Reader& r) {
  auto f = std::make_shared<FrameFeatures>();
  f->keypoints = r.getArray<Keypoint>("keypoints");
  f->keypointsUn = r.getArray<Keypoint>("undistorted keypoints");
  f->descriptors = r.getArray<OrbDescriptor>("descriptors");
  f->uRight = r.getArray<float>("uRight");
  f->depth = r.getArray<float>("depth");
  const std::size_t n = f->keypoints.size();
  if (f->keypointsUn.size() != n || f->descriptors.size() != n || f->uRight.size() != n || f->depth.size() != n)
    r.fail("keyframe feature arrays of different lengths");
  f->closeDepth = r.get<float>("close depth");
  f->scales.scale = r.getArray<float>("scale table");
  f->scales.invScale = r.getArray<float>("scale table");
  f->scales.sigma2 = r.getArray<float>("scale table");
  f->scales.invSigma2 = r.getArray<float>("scale table");
  const std::size_t levels = f->scales.scale.size();
  if (levels == 0 || f->scales.invScale.size() != levels || f->scales.sigma2.size() != levels ||
      f->scales.invSigma2.size() != levels)
    r.fail("scale tables of different lengths");
  for (const std::vector<Keypoint>* kps : {&f->keypoints, &f->keypointsUn})
    for (const Keypoint& k : *kps)
      if (k.octave < 0 || static_cast<std::size_t>(k.octave) >= levels) r.fail("keypoint octave out of range");
  float bounds[4];
  for (float& b : bounds) b = r.get<float>("grid bounds");
  f->grid.build(f->keypointsUn, bounds[0], bounds[1], bounds[2], bounds[3]);
  return f;
}

bow::FeatureVector featureVectorOf(const std::vector<NodeFeature>& groups) {
  std::vector<std::pair<bow::NodeId, std::uint32_t>> pairs;
  pairs.reserve(groups.size());
  for (const NodeFeature& g : groups) pairs.emplace_back(g.node, g.feature);
  return bow::FeatureVector::fromPairs(std::move(pairs));
}

std::vector<char> readWholeFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw fileError(file.string(), "cannot open map file for reading");
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw fileError(file.string(), "read error");
  return bytes;
}

void checkCamera(const std::string& file, const MapIntrinsics& saved, const MapIntrinsics& expected) {
  const std::pair<const char*, std::pair<double, double>> values[] = {
      {"fx", {saved.fx, expected.fx}}, {"fy", {saved.fy, expected.fy}}, {"cx", {saved.cx, expected.cx}},
      {"cy", {saved.cy, expected.cy}}, {"bf", {saved.bf, expected.bf}}};
  for (const auto& [key, v] : values)
    if (std::abs(v.first - v.second) > 1e-6 * std::max(1.0, std::abs(v.second)))
      throw Error(file, std::string("key ") + key,
                  std::string("map made with a different camera: ") + key + " = " + std::to_string(v.first) +
                      " in the map, " + std::to_string(v.second) + " in this system");
}

}  // namespace

std::uint64_t vocabularyChecksum(const OrbVocabulary& vocabulary) {
  const auto bytes = vocabulary.blob().bytes();
  return bow::checksum64(bytes.data(), bytes.size());
}

void sealMapFileBytes(std::span<char> bytes) {
  const std::uint64_t size = bytes.size();
  std::memcpy(bytes.data() + kDeclaredSizeOffset, &size, sizeof size);
  const std::uint64_t checksum = bow::checksum64(bytes.data(), bytes.size() - kTrailerBytes);
  std::memcpy(bytes.data() + bytes.size() - kTrailerBytes, &checksum, sizeof checksum);
}

void writeMapFile(const fs::path& file, const Map& map, const MapFileInfo& info) {
  const std::vector<KeyFrame*> keyFrames = map.keyFrames();
  const std::vector<MapPoint*> points = map.mapPoints();
  Writer w;
  for (char c : kMagic) w.put(c);
  w.put(kMapFileVersion);
  w.put(static_cast<std::uint32_t>(info.sensor));
  w.put<std::uint64_t>(0);  // file size (kDeclaredSizeOffset), filled in by sealMapFileBytes
  w.put(info.vocabularyChecksum);
  w.putIntrinsics(info.intrinsics);
  w.put<std::uint64_t>(keyFrames.size());
  w.put<std::uint64_t>(points.size());
  w.put<std::uint32_t>(info.metricScale ? 1 : 0);

  for (const KeyFrame* kf : keyFrames) {
    w.put<std::uint64_t>(kf->id);
    w.put<std::uint64_t>(kf->frameIndex);
    w.put(kf->timestamp);
    w.putPose(kf->Tcw());
    w.putIntrinsics(kf->intrinsics);
    writeFeatures(w, kf->features());
    // Field by field: WordEntry has padding, whose bytes would make the file nondeterministic.
    w.put<std::uint64_t>(kf->bowVector().size());
    for (const bow::WordEntry& e : kf->bowVector()) {
      w.put(e.word);
      w.put(e.weight);
    }
    std::vector<NodeFeature> groups;
    const bow::FeatureVector& fv = kf->featureVector();
    for (std::size_t g = 0; g < fv.size(); ++g)
      for (std::uint32_t feature : fv.featuresOf(g)) groups.push_back({fv.node(g), feature});
    w.putArray(groups);
    // Culling re-parents the children of a culled keyframe, so a good keyframe's parent is good.
    const KeyFrame* parent = kf->parent();
    w.put<std::int64_t>(parent ? static_cast<std::int64_t>(parent->id) : -1);
    std::vector<std::uint64_t> loops;
    for (const KeyFrame* l : kf->loopEdges())
      if (!l->isBad()) loops.push_back(l->id);
    w.putArray(loops);
    std::vector<Edge> edges;
    for (const KeyFrame* c : kf->covisibles())
      if (!c->isBad()) edges.push_back({c->id, kf->weight(c)});
    w.putArray(edges);
  }
  for (const MapPoint* p : points) {
    std::vector<Observation> observations;
    for (const auto& [kf, index] : p->observations())
      if (!kf->isBad()) observations.push_back({kf->id, index});
    // A point's reference keyframe may have been culled: any observer will do.
    const KeyFrame* reference = p->reference();
    if ((!reference || reference->isBad()) && !p->observations().empty()) reference = p->observations().begin()->first;
    w.put<std::uint64_t>(p->id);
    for (int i = 0; i < 3; ++i) w.put(p->position()(i));
    w.put<std::int64_t>(reference ? static_cast<std::int64_t>(reference->id) : -1);
    w.put<std::uint64_t>(p->firstFrame);
    w.put(p->descriptor());
    w.put<std::int32_t>(p->visible());
    w.put<std::int32_t>(p->found());
    w.putArray(observations);
  }
  // The atlas (version 3): the maps' records, the active map, each keyframe's map and flags.
  w.put<std::uint64_t>(map.mapRecords().size());
  for (const AtlasMapRecord& m : map.mapRecords()) {
    w.put<std::uint64_t>(m.startFrame);
    w.put<std::int64_t>(m.mergedInto ? static_cast<std::int64_t>(*m.mergedInto) : -1);
  }
  w.put<std::uint32_t>(map.activeMapId());
  for (const KeyFrame* kf : keyFrames) {
    w.put<std::uint32_t>(kf->mapId());
    w.put<std::uint8_t>(static_cast<std::uint8_t>((kf->isMapRoot() ? kRootFlag : 0) | (kf->isGauge() ? kGaugeFlag : 0)));
  }
  w.put<std::uint64_t>(0);  // the trailer, filled in by sealMapFileBytes
  sealMapFileBytes(w.bytes());
  writeFileAtomically(file, w.bytes());
}

namespace {

// Checks size, magic, version, declared size and checksum of a whole map file; returns its header
// and sets headerEnd to where the keyframes begin (the header's length depends on the version).
MapFileInfo checkedHeader(const std::vector<char>& bytes, const std::string& file, std::size_t& headerEnd) {
  if (bytes.size() < kHeaderBytesVersion1 + kTrailerBytes)
    throw fileError(file, "truncated map file: " + std::to_string(bytes.size()) + " bytes, shorter than the header");
  if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw fileError(file, "not an orbis map file (bad magic)");
  Reader header(bytes, bytes.size(), file);
  for (std::size_t i = 0; i < sizeof kMagic; ++i) header.get<char>("magic");
  const auto version = header.get<std::uint32_t>("version");
  if (version == 0 || version > kMapFileVersion)
    throw fileError(file, "map file format version " + std::to_string(version) + ", this orbis reads versions 1 to " +
                              std::to_string(kMapFileVersion));
  MapFileInfo info;
  const auto sensor = header.get<std::uint32_t>("sensor");
  const auto declaredSize = header.get<std::uint64_t>("file size");
  if (declaredSize != bytes.size())
    throw fileError(file, (bytes.size() < declaredSize ? "truncated map file: " : "map file with trailing bytes: ") +
                              std::to_string(bytes.size()) + " bytes, the header declares " +
                              std::to_string(declaredSize));
  std::uint64_t storedChecksum;
  std::memcpy(&storedChecksum, bytes.data() + bytes.size() - kTrailerBytes, sizeof storedChecksum);
  if (bow::checksum64(bytes.data(), bytes.size() - kTrailerBytes) != storedChecksum)
    throw fileError(file, "corrupt map file: checksum mismatch");

  if (sensor > static_cast<std::uint32_t>(SensorKind::Rgbd)) header.fail("unknown sensor kind");
  info.sensor = static_cast<SensorKind>(sensor);
  info.vocabularyChecksum = header.get<std::uint64_t>("vocabulary checksum");
  info.intrinsics = header.getIntrinsics("camera");
  info.keyFrames = header.get<std::uint64_t>("keyframe count");
  info.mapPoints = header.get<std::uint64_t>("map point count");
  if (version >= kFirstVersionWithScale) {
    const auto scale = header.get<std::uint32_t>("scale flag");
    if (scale > 1) header.fail("scale flag neither metric (1) nor arbitrary (0)");
    info.metricScale = scale == 1;
  } else {
    info.metricScale = info.sensor != SensorKind::Monocular;  // version 1: monocular was the only such sensor
  }
  info.version = version;
  headerEnd = header.position();
  return info;
}

}  // namespace

MapFileInfo readMapFileInfo(const fs::path& path) {
  std::size_t headerEnd = 0;
  return checkedHeader(readWholeFile(path), path.string(), headerEnd);
}

MapFileInfo readMapFile(const fs::path& path, Map& map, const MapFileInfo& expected) {
  const std::string file = path.string();
  if (map.createdKeyFrames() != 0 || map.createdMapPoints() != 0)
    throw fileError(file, "a map file can only be loaded into an empty map");
  const std::vector<char> bytes = readWholeFile(path);
  std::size_t headerEnd = 0;
  const MapFileInfo info = checkedHeader(bytes, file, headerEnd);
  if (info.sensor != expected.sensor)
    throw fileError(file, "map made with sensor " + std::string(toString(info.sensor)) + ", this system's sensor is " +
                              std::string(toString(expected.sensor)));
  if (info.vocabularyChecksum != expected.vocabularyChecksum)
    throw fileError(file, "map made with another vocabulary (checksum " + std::to_string(info.vocabularyChecksum) +
                              ", this system's vocabulary has " + std::to_string(expected.vocabularyChecksum) + ")");
  if (info.metricScale != expected.metricScale)
    throw fileError(file, std::string("map with ") + (info.metricScale ? "metric" : "arbitrary") +
                              " scale, this system's sensor needs " + (expected.metricScale ? "metric" : "arbitrary") +
                              " scale");
  checkCamera(file, info.intrinsics, expected.intrinsics);

  // Parse everything before touching the map, so a defect leaves it empty.
  struct KeyFrameRecord {
    std::uint64_t id, frameIndex;
    double timestamp;
    SE3d Tcw;
    MapIntrinsics intrinsics;
    std::shared_ptr<const FrameFeatures> features;
    std::vector<bow::WordEntry> bow;
    std::vector<NodeFeature> groups;
    std::int64_t parent;
    std::vector<std::uint64_t> loops;
    std::vector<Edge> edges;
  };
  struct PointRecord {
    std::uint64_t id;
    Eigen::Vector3d position;
    std::int64_t reference;
    std::uint64_t firstFrame;
    OrbDescriptor descriptor;
    std::int32_t visible, found;
    std::vector<Observation> observations;
  };
  Reader r(bytes, bytes.size() - kTrailerBytes, file);
  for (std::size_t i = 0; i < headerEnd; ++i) r.get<char>("header");
  std::vector<KeyFrameRecord> keyFrames;
  std::unordered_map<std::uint64_t, std::size_t> keyFrameIndex;
  for (std::uint64_t k = 0; k < info.keyFrames; ++k) {
    KeyFrameRecord kf;
    kf.id = r.get<std::uint64_t>("keyframe id");
    kf.frameIndex = r.get<std::uint64_t>("keyframe");
    kf.timestamp = r.get<double>("keyframe");
    kf.Tcw = r.getPose("keyframe pose");
    kf.intrinsics = r.getIntrinsics("keyframe camera");
    // Not saved: how much BA trusts depth readings is the running system's noise model.
    kf.intrinsics.disparitySigma = expected.intrinsics.disparitySigma;
    kf.features = readFeatures(r);
    kf.bow.resize(r.count(sizeof(bow::WordId) + sizeof(bow::WordValue), "bag of words"));
    for (bow::WordEntry& e : kf.bow) {
      e.word = r.get<bow::WordId>("bag of words");
      e.weight = r.get<bow::WordValue>("bag of words");
    }
    if (expected.vocabularyWords > 0)
      for (const bow::WordEntry& e : kf.bow)
        if (e.word >= expected.vocabularyWords) r.fail("word id beyond this system's vocabulary");
    kf.groups = r.getArray<NodeFeature>("feature vector");
    for (const NodeFeature& g : kf.groups) {
      if (g.feature >= kf.features->size()) r.fail("feature vector index out of range");
      if (expected.vocabularyNodes > 0 && g.node >= expected.vocabularyNodes)
        r.fail("feature vector node beyond this system's vocabulary");
    }
    kf.parent = r.get<std::int64_t>("spanning-tree parent");
    kf.loops = r.getArray<std::uint64_t>("loop edges");
    kf.edges = r.getArray<Edge>("covisibility edges");
    if (!keyFrameIndex.emplace(kf.id, keyFrames.size()).second) r.fail("duplicate keyframe id");
    keyFrames.push_back(std::move(kf));
  }
  auto known = [&](std::uint64_t id) { return keyFrameIndex.count(id) != 0; };
  // The graphs must be ones the running system could have built: an edge to itself, a negative
  // weight or a cycle in the spanning tree would send later graph walks (essential graph, culling
  // re-parenting) into loops the checks above cannot see.
  for (const KeyFrameRecord& kf : keyFrames) {
    if (kf.parent >= 0 && !known(static_cast<std::uint64_t>(kf.parent))) r.fail("parent is not a saved keyframe");
    if (kf.parent >= 0 && static_cast<std::uint64_t>(kf.parent) == kf.id) r.fail("keyframe is its own parent");
    for (std::uint64_t l : kf.loops)
      if (!known(l) || l == kf.id) r.fail("loop edge to a keyframe not saved, or to itself");
    for (const Edge& e : kf.edges)
      if (!known(e.keyFrame) || e.keyFrame == kf.id || e.weight < 0 || e.weight > std::numeric_limits<int>::max())
        r.fail("covisibility edge to a keyframe not saved, to itself, or with an impossible weight");
  }
  for (const KeyFrameRecord& kf : keyFrames) {
    std::int64_t parent = kf.parent;
    for (std::size_t steps = 0; parent >= 0; ++steps) {
      if (steps > keyFrames.size()) r.fail("cycle in the spanning tree");
      parent = keyFrames[keyFrameIndex.at(static_cast<std::uint64_t>(parent))].parent;
    }
  }
  std::vector<PointRecord> points;
  std::unordered_set<std::uint64_t> pointIds;
  // Each keypoint of a keyframe holds at most one point, and a point observes a keyframe once.
  std::vector<std::vector<bool>> slotTaken(keyFrames.size());
  for (std::size_t k = 0; k < keyFrames.size(); ++k) slotTaken[k].assign(keyFrames[k].features->size(), false);
  for (std::uint64_t k = 0; k < info.mapPoints; ++k) {
    PointRecord p;
    p.id = r.get<std::uint64_t>("map point id");
    for (int i = 0; i < 3; ++i) p.position(i) = r.get<double>("map point position");
    p.reference = r.get<std::int64_t>("map point reference");
    p.firstFrame = r.get<std::uint64_t>("map point");
    p.descriptor = r.get<OrbDescriptor>("map point descriptor");
    p.visible = r.get<std::int32_t>("map point counters");
    p.found = r.get<std::int32_t>("map point counters");
    p.observations = r.getArray<Observation>("observations");
    if (!pointIds.insert(p.id).second) r.fail("duplicate map point id");
    if (!p.position.allFinite()) r.fail("non-finite map point position");
    if (p.reference < 0 || !known(static_cast<std::uint64_t>(p.reference))) r.fail("map point reference not saved");
    std::unordered_set<std::uint64_t> observers;
    for (const Observation& o : p.observations) {
      if (!known(o.keyFrame) || o.index >= keyFrames[keyFrameIndex[o.keyFrame]].features->size())
        r.fail("observation of an unknown keyframe or keypoint");
      if (!observers.insert(o.keyFrame).second) r.fail("map point observes a keyframe twice");
      std::vector<bool>::reference taken = slotTaken[keyFrameIndex[o.keyFrame]][o.index];
      if (taken) r.fail("keypoint observed by two map points");
      taken = true;
    }
    points.push_back(std::move(p));
  }
  // The atlas (version 3); an older file holds one map.
  std::vector<AtlasMapRecord> maps{AtlasMapRecord{}};
  std::uint32_t activeMap = 0;
  std::vector<std::pair<std::uint32_t, std::uint8_t>> keyFrameMaps(keyFrames.size(), {0, 0});
  if (info.version >= kFirstVersionWithAtlas) {
    maps.resize(r.count(16, "atlas maps"));
    if (maps.empty()) r.fail("atlas without maps");
    for (std::size_t m = 0; m < maps.size(); ++m) {
      maps[m].id = static_cast<std::uint32_t>(m);
      maps[m].startFrame = r.get<std::uint64_t>("atlas map");
      const auto into = r.get<std::int64_t>("atlas map");
      if (into >= static_cast<std::int64_t>(maps.size()) || into == static_cast<std::int64_t>(m) || into < -1)
        r.fail("atlas map merged into an unknown map or itself");
      if (into >= 0) maps[m].mergedInto = static_cast<std::uint32_t>(into);
    }
    activeMap = r.get<std::uint32_t>("active map");
    if (activeMap >= maps.size() || maps[activeMap].mergedInto) r.fail("active map unknown or merged");
    for (auto& [mapId, flags] : keyFrameMaps) {
      mapId = r.get<std::uint32_t>("keyframe map");
      flags = r.get<std::uint8_t>("keyframe map flags");
      if (mapId >= maps.size() || maps[mapId].mergedInto) r.fail("keyframe in an unknown or merged map");
      if (flags > (kRootFlag | kGaugeFlag) || (flags == kGaugeFlag)) r.fail("impossible keyframe map flags");
    }
  }
  if (r.position() != bytes.size() - kTrailerBytes) r.fail("unexpected bytes after the last map point");

  std::vector<KeyFrame*> created;
  created.reserve(keyFrames.size());
  for (KeyFrameRecord& kf : keyFrames)
    created.push_back(map.createKeyFrame(kf.frameIndex, kf.timestamp, kf.Tcw, kf.features, kf.intrinsics,
                                         bow::BowVector::fromUnsorted(std::move(kf.bow), false),
                                         featureVectorOf(kf.groups)));
  auto keyFrameOf = [&](std::uint64_t id) { return created[keyFrameIndex.at(id)]; };
  for (const PointRecord& p : points) {
    MapPoint* point = map.createMapPoint(p.position, keyFrameOf(static_cast<std::uint64_t>(p.reference)), p.firstFrame);
    for (const Observation& o : p.observations) {
      KeyFrame* keyFrame = keyFrameOf(o.keyFrame);
      point->addObservation(keyFrame, o.index);
      keyFrame->setPoint(o.index, point);
    }
    point->setDescriptor(p.descriptor);
    point->updateNormalAndDepth();
    point->increaseVisible(p.visible - point->visible());
    point->increaseFound(p.found - point->found());
  }
  for (std::size_t k = 0; k < keyFrames.size(); ++k) {
    KeyFrame* kf = created[k];
    for (const Edge& e : keyFrames[k].edges) kf->addConnection(keyFrameOf(e.keyFrame), static_cast<int>(e.weight));
    if (keyFrames[k].parent >= 0) kf->changeParent(keyFrameOf(static_cast<std::uint64_t>(keyFrames[k].parent)));
    for (std::uint64_t l : keyFrames[k].loops) kf->addLoopEdge(keyFrameOf(l));
  }
  if (info.version >= kFirstVersionWithAtlas) {
    for (std::size_t k = 0; k < keyFrames.size(); ++k) {
      created[k]->setMapId(keyFrameMaps[k].first);
      created[k]->setMapRoot((keyFrameMaps[k].second & kRootFlag) != 0);
      created[k]->setGauge((keyFrameMaps[k].second & kGaugeFlag) != 0);
    }
    map.restoreAtlas(std::move(maps), activeMap);
  }
  return info;
}

}  // namespace orbis
