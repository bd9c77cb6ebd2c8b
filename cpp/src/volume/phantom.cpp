// A procedural temporal bone: shapes in millimetres painted into the grid in order, each over the
// voxels of its own bounding box only.

#include "ambfplus/volume/phantom.h"
#include "ambfplus/errors.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <stdexcept>
#include <thread>

#include "volume/grid_access.h"

namespace ambfplus {
namespace {

using V3 = Eigen::Vector3d;

constexpr double kSizeMm = 48.0;

enum : std::uint8_t {
  kEmpty = 0,
  kBone = 1,
  kSinusDura = 2,
  kFacialNerve = 3,
  kChordaTympani = 4,
  kLabyrinth = 5,
  kMalleus = 6,
  kIncus = 7,
  kStapes = 8,
  kEac = 9,
  kCarotid = 10,
};

// Portable random numbers (the same on every platform and compiler), from a seed.
class SplitMix {
 public:
  explicit SplitMix(std::uint64_t seed) : state_(seed) {}
  double uniform(double lo, double hi) {
    state_ += 0x9E3779B97F4A7C15ull;
    std::uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return lo + (hi - lo) * (static_cast<double>(z >> 11) * (1.0 / 9007199254740992.0));
  }

 private:
  std::uint64_t state_;
};

// Smooth value noise in [-1, 1] with features about one lattice unit wide.
double value_noise(const V3& p, std::uint64_t seed) {
  auto lattice = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    SplitMix h(seed ^ (static_cast<std::uint64_t>(x) * 0x9E3779B1ull) ^
               (static_cast<std::uint64_t>(y) * 0x85EBCA77ull) ^
               (static_cast<std::uint64_t>(z) * 0xC2B2AE3Dull));
    return h.uniform(-1, 1);
  };
  const V3 f = p.array().floor();
  V3 t = p - f;
  t = t.cwiseProduct(t).cwiseProduct(V3::Constant(3) - 2 * t);  // smoothstep
  const auto x = static_cast<std::int64_t>(f.x()), y = static_cast<std::int64_t>(f.y()),
             z = static_cast<std::int64_t>(f.z());
  double v = 0;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    v += lattice(x + dx, y + dy, z + dz) * (dx ? t.x() : 1 - t.x()) * (dy ? t.y() : 1 - t.y()) *
         (dz ? t.z() : 1 - t.z());
  }
  return v;
}

double segment_distance(const V3& p, const V3& a, const V3& b) {
  const V3 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

double polyline_distance(const V3& p, const std::vector<V3>& pts) {
  double d = 1e9;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i)
    d = std::min(d, segment_distance(p, pts[i], pts[i + 1]));
  return d;
}

double torus_distance(const V3& p, const V3& centre, const V3& axis, double major) {
  const V3 n = axis.normalized();
  const V3 q = p - centre;
  const double h = q.dot(n);
  const double radial = (q - h * n).norm();
  return std::hypot(radial - major, h);
}

class Painter {
 public:
  Painter(VolumeData& v) : v_(v), labels_(static_cast<std::uint8_t*>(v.label_data())) {}

  // Sets `label` where inside(p) holds and allowed(old label) holds, over the box [lo, hi] (mm).
  void paint(const V3& lo, const V3& hi, const std::function<bool(const V3&)>& inside,
             std::uint8_t label, const std::function<bool(std::uint8_t)>& allowed = nullptr) {
    const auto& n = v_.shape();
    int a[3], b[3];
    for (int ax = 0; ax < 3; ++ax) {
      const double scale = n[ax] / kSizeMm;
      a[ax] = std::clamp(static_cast<int>(std::floor((lo[ax] + kSizeMm / 2) * scale)), 0, n[ax]);
      b[ax] = std::clamp(static_cast<int>(std::ceil((hi[ax] + kSizeMm / 2) * scale)) + 1, 0, n[ax]);
    }
    auto slab = [&](int k0, int k1) {
      for (int k = k0; k < k1; ++k) {
        for (int j = a[1]; j < b[1]; ++j) {
          for (int i = a[0]; i < b[0]; ++i) {
            std::uint8_t& l = labels_[v_.linear_index(i, j, k)];
            if (allowed && !allowed(l)) continue;
            if (inside(centre_mm(i, j, k))) l = label;
          }
        }
      }
    };
    // Large boxes on two threads over disjoint slabs (the result does not depend on the split).
    const int mid = (a[2] + b[2]) / 2;
    if (std::int64_t(b[0] - a[0]) * (b[1] - a[1]) * (b[2] - a[2]) > (1 << 18)) {
      std::thread other(slab, a[2], mid);
      slab(mid, b[2]);
      other.join();
    } else {
      slab(a[2], b[2]);
    }
  }

  // A tube along a polyline; with `within`, only where within(p) holds.
  void tube(const std::vector<V3>& pts, double r, std::uint8_t label,
            const std::function<bool(const V3&)>& within = nullptr) {
    V3 lo = pts[0], hi = pts[0];
    for (const V3& p : pts) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    paint(
        lo.array() - r, hi.array() + r,
        [&](const V3& p) { return polyline_distance(p, pts) <= r && (!within || within(p)); },
        label);
  }

  void torus(const V3& centre, const V3& axis, double major, double minor, std::uint8_t label) {
    const double reach = major + minor;
    paint(
        centre.array() - reach, centre.array() + reach,
        [&](const V3& p) { return torus_distance(p, centre, axis, major) <= minor; }, label);
  }

  void sphere(const V3& c, double r, std::uint8_t label,
              const std::function<bool(std::uint8_t)>& allowed = nullptr) {
    paint(
        c.array() - r, c.array() + r, [&](const V3& p) { return (p - c).norm() <= r; }, label,
        allowed);
  }

 private:
  V3 centre_mm(int i, int j, int k) const {
    const auto& n = v_.shape();
    return V3((i + 0.5) * kSizeMm / n[0] - kSizeMm / 2, (j + 0.5) * kSizeMm / n[1] - kSizeMm / 2,
              (k + 0.5) * kSizeMm / n[2] - kSizeMm / 2);
  }

  VolumeData& v_;
  std::uint8_t* labels_;
};

}  // namespace

LabelTable phantom_label_table() {
  return LabelTable({
      {kBone, "Bone", {240, 232, 205}, true, false},
      {kSinusDura, "Sinus_Dura", {95, 140, 215}, true, true},
      {kFacialNerve, "Facial_Nerve", {250, 215, 40}, true, true},
      {kChordaTympani, "Chorda_Tympani", {200, 170, 30}, true, true},
      {kLabyrinth, "Bony_Labyrinth", {120, 200, 120}, true, true},
      {kMalleus, "Malleus", {215, 60, 230}, true, false},
      {kIncus, "Incus", {40, 225, 160}, true, false},
      {kStapes, "Stapes", {90, 60, 240}, true, false},
      {kEac, "EAC", {245, 200, 190}, true, false},
      {kCarotid, "ICA", {220, 70, 60}, true, true},
  });
}

std::shared_ptr<VolumeData> make_temporal_bone_phantom(int resolution, std::uint32_t seed) {
  if (resolution < 16 || resolution > 2048) {
    throw ArgumentError("phantom resolution must be 16..2048 voxels, got " +
                        std::to_string(resolution));
  }
  auto volume = std::make_shared<VolumeData>(std::array<int, 3>{resolution, resolution, resolution},
                                             V3::Constant(kSizeMm / 1000.0), LabelType::kUInt8,
                                             phantom_label_table());
  Painter paint(*volume);
  auto only = [](std::uint8_t label) { return [label](std::uint8_t l) { return l == label; }; };

  SplitMix rng(0x5eed0000ull + seed);

  // Bone: a rounded block whose lateral face (z = +12 mm) is where drilling starts, its surface
  // rippled by a few random waves so that it looks like bone rather than a machined part, with a
  // fine grain near the surface as a segmented CT has.
  struct Wave {
    V3 k;
    double phase, amplitude;
  };
  std::vector<Wave> waves;
  for (int w = 0; w < 6; ++w) {
    const V3 dir = V3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)).normalized();
    waves.push_back(
        {dir * rng.uniform(0.15, 0.45), rng.uniform(0, 6.283), rng.uniform(0.01, 0.025)});
  }
  const V3 bone_c(0, 0, -2), bone_r(21, 19, 14);
  constexpr double kRoughness = 0.035;
  auto bone_value = [&](const V3& p, double ripple, double grow) {
    const V3 q = (p - bone_c).cwiseQuotient(bone_r * ripple * grow);
    const V3 q2 = q.cwiseProduct(q);
    return q2.squaredNorm();  // x^4 + y^4 + z^4: 1 on the surface
  };
  auto ripple_at = [&](const V3& p) {
    double r = 1.0;
    for (const Wave& w : waves) r += w.amplitude * std::sin(w.k.dot(p) + w.phase);
    return r;
  };
  {
    // sin(kx x + ky y + kz z + phase) for every voxel from per-axis complex exponentials.
    const int n = resolution;
    const double step = kSizeMm / n;
    std::vector<std::vector<std::complex<double>>> ex(waves.size()), ey(waves.size()),
        ez(waves.size());
    for (std::size_t w = 0; w < waves.size(); ++w) {
      for (int i = 0; i < n; ++i) {
        const double c = (i + 0.5) * step - kSizeMm / 2;
        ex[w].push_back(std::polar(1.0, waves[w].k.x() * c + waves[w].phase));
        ey[w].push_back(std::polar(1.0, waves[w].k.y() * c));
        ez[w].push_back(std::polar(1.0, waves[w].k.z() * c));
      }
    }
    auto* labels = static_cast<std::uint8_t*>(volume->label_data());
    auto slab = [&](int k0, int k1) {
      for (int k = k0; k < k1; ++k) {
        for (int j = 0; j < n; ++j) {
          for (int i = 0; i < n; ++i) {
            double ripple = 1.0;
            for (std::size_t w = 0; w < waves.size(); ++w) {
              // Im(ex * ey * ez), written out (std::complex's operator* checks for NaNs).
              const auto &a = ex[w][i], &b = ey[w][j], &c = ez[w][k];
              const double re = a.real() * b.real() - a.imag() * b.imag();
              const double im = a.real() * b.imag() + a.imag() * b.real();
              ripple += waves[w].amplitude * (re * c.imag() + im * c.real());
            }
            const V3 p((i + 0.5) * step - kSizeMm / 2, (j + 0.5) * step - kSizeMm / 2,
                       (k + 0.5) * step - kSizeMm / 2);
            const double f = bone_value(p, ripple, 1.0);
            const bool inside = std::abs(f - 1.0) > kRoughness
                                    ? f <= 1.0
                                    : f <= 1.0 + kRoughness * value_noise(p / 1.1, seed);
            if (inside) labels[volume->linear_index(i, j, k)] = kBone;
          }
        }
      }
    };
    // Two threads over disjoint slabs: the result does not depend on the split.
    std::thread other(slab, 0, n / 2);
    slab(n / 2, n);
    other.join();
  }

  // Mastoid air cells: random cavities in the posterior, lateral bone.
  const int cells = 70;
  for (int c = 0; c < cells; ++c) {
    const V3 centre(rng.uniform(-18, -3), rng.uniform(-13, 12), rng.uniform(-6, 9));
    const double r = rng.uniform(0.7, 2.3);
    paint.sphere(centre, r, kEmpty, only(kBone));
  }

  // External auditory canal: an open lumen from the lateral face, lined with canal skin.
  const std::vector<V3> eac = {V3(9, -2, 13), V3(7, -2, 4), V3(6, -1.5, 0)};
  paint.tube(eac, 4.3, kEac);
  paint.tube({V3(9.5, -2, 22), V3(9, -2, 13), V3(7, -2, 4), V3(6, -1.5, 0)}, 3.5, kEmpty);

  // Middle ear: an air-filled cavity medial to the canal holding the ossicles.
  paint.paint(
      V3(1, -6, -6), V3(9, 4, 0),
      [](const V3& p) {
        const V3 q = (p - V3(5, -1, -3)).cwiseQuotient(V3(4, 5, 2.6));
        return q.squaredNorm() <= 1.0;
      },
      kEmpty);
  paint.sphere(V3(6, 2, -2), 1.2, kMalleus);
  paint.tube({V3(6, 1.5, -1.6), V3(6.5, -2.8, -2.4)}, 0.65, kMalleus);
  paint.sphere(V3(4.4, 1.8, -3), 1.1, kIncus);
  paint.tube({V3(4.4, 1.5, -3), V3(3.6, -2.2, -3.3)}, 0.55, kIncus);
  paint.tube({V3(3.6, -2.3, -3.5), V3(2.9, -2.6, -5.3)}, 0.45, kStapes);

  // Sigmoid sinus along the posterior edge, and dura over the middle cranial fossa.
  // Structures stay within the bone (grown a little, as vessels bulge from it).
  auto in_bone = [&](const V3& p) { return bone_value(p, ripple_at(p), 1.03) <= 1.0; };
  paint.tube(
      {V3(-19, 15, -4), V3(-16, 6, -7), V3(-13, -4, -8), V3(-10, -12, -10), V3(-6, -18, -12)}, 3.2,
      kSinusDura, in_bone);
  paint.paint(
      V3(-18, 14, -14), V3(16, 15.4, 5), [](const V3&) { return true; }, kSinusDura, only(kBone));

  // Facial nerve: tympanic segment, second genu, descending (mastoid) segment.
  const std::vector<V3> facial = {V3(10, 4, -6),    V3(4, 3, -4.8),    V3(0, 1, -4.2),
                                  V3(-2, -3, -3.2), V3(-3, -10, -2.2), V3(-3, -17, -1.5)};
  paint.tube(facial, 0.9, kFacialNerve);
  paint.tube({V3(-3, -9, -2.2), V3(0.5, -5, -1.8), V3(4.5, -0.5, -1.6)}, 0.35, kChordaTympani);

  // Labyrinth: vestibule, three semicircular canals in roughly orthogonal planes, the cochlea.
  paint.sphere(V3(0, 3, -8.5), 1.9, kLabyrinth);
  paint.torus(V3(-2.5, 3.5, -7), V3(0.1, 1, 0.35), 3.0, 0.55, kLabyrinth);  // lateral
  paint.torus(V3(0, 6.8, -9), V3(1, 0.1, 0.2), 3.2, 0.55, kLabyrinth);      // superior
  paint.torus(V3(-3.5, 4, -10.5), V3(0.2, 0.3, 1), 3.0, 0.55, kLabyrinth);  // posterior
  const V3 cochlea_axis = V3(1, 0, 0.5).normalized();
  for (int turn = 0; turn < 3; ++turn) {
    paint.torus(V3(5.5, 3, -10) + cochlea_axis * (0.9 * turn), cochlea_axis, 3.0 - 0.8 * turn,
                0.85 - 0.12 * turn, kLabyrinth);
  }

  // Internal carotid artery, deep and anterior.
  paint.tube({V3(12, -19, -13), V3(10, -8, -12), V3(8, 0, -13), V3(9, 9, -12)}, 2.3, kCarotid,
             in_bone);

  volume->commit();
  volume->set_source("phantom(resolution=" + std::to_string(resolution) +
                     ", seed=" + std::to_string(seed) + ")");
  return volume;
}

}  // namespace ambfplus
