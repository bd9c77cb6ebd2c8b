// A procedural temporal bone built from the anatomy's landmarks: a skull block and the dura of the
// middle and posterior fossae in one pass over the grid, then each structure painted over the
// voxels of its own bounding box. Millimetres in the phantom frame: x anterior, y superior,
// z lateral (for a right ear; a left ear mirrors x), the grid centred on the origin.

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

// The ids, names and colours of the original system's segmented ear (its labels.csv in file
// order), so that scripts, tasks and datasets run unchanged on phantoms and patient volumes.
enum : std::uint8_t {
  kEmpty = 0,
  kBone = 1,
  kMalleus = 2,
  kIncus = 3,
  kStapes = 4,
  kLabyrinth = 5,
  kIac = 6,
  kSuperiorVestibularNerve = 7,
  kInferiorVestibularNerve = 8,
  kCochlearNerve = 9,
  kFacialNerve = 10,
  kChordaTympani = 11,
  kCarotid = 12,
  kSinusDura = 13,
  kVestibularAqueduct = 14,
  kTmj = 15,
  kEac = 16,
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
  V3 jitter(double a) { return V3(uniform(-a, a), uniform(-a, a), uniform(-a, a)); }

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

double torus_distance(const V3& p, const V3& centre, const V3& axis, double major) {
  const V3 n = axis.normalized();
  const V3 q = p - centre;
  const double h = q.dot(n);
  const double radial = (q - h * n).norm();
  return std::hypot(radial - major, h);
}

// x^4 + y^4 + z^4 of the point scaled into a box's half-extents: 1 on a rounded box's surface.
double superellipsoid(const V3& p, const V3& centre, const V3& radii) {
  const V3 q = (p - centre).cwiseQuotient(radii);
  return q.cwiseProduct(q).squaredNorm();
}

// Threads for the passes over the grid; results never depend on how the slabs are split.
int worker_count() {
  return static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
}

// Runs body(k0, k1) over [lo, hi) split into slabs on several threads when the work is large.
void parallel_slabs(int lo, int hi, std::int64_t voxels,
                    const std::function<void(int, int)>& body) {
  const int workers = voxels > (1 << 18) ? std::min(worker_count(), hi - lo) : 1;
  if (workers <= 1) {
    body(lo, hi);
    return;
  }
  std::vector<std::thread> threads;
  for (int w = 1; w < workers; ++w) {
    threads.emplace_back(body, lo + (hi - lo) * w / workers, lo + (hi - lo) * (w + 1) / workers);
  }
  body(lo, lo + (hi - lo) / workers);
  for (auto& t : threads) t.join();
}

// What the seed varies, each within an anatomical range (docs/guide/volumes.md names the
// sources). Lengths in millimetres.
struct Anatomy {
  double eac_radius, tegmen_height, dura_thickness, sinus_radius, facial_radius, carotid_radius;
  double iac_radius, cochlea_radius, canal_radius, ossicle_scale, tmj_scale;
  double air_cells, air_cell_max_radius;
  V3 eac_shift, sinus_shift, facial_shift, labyrinth_shift, carotid_shift;
};

Anatomy sample_anatomy(SplitMix& rng) {
  Anatomy a;
  a.eac_radius = rng.uniform(4.2, 5.0);
  a.tegmen_height = rng.uniform(8.8, 11.0);
  a.dura_thickness = rng.uniform(4.0, 5.5);
  a.sinus_radius = rng.uniform(3.2, 4.6);
  a.facial_radius = rng.uniform(0.75, 0.95);
  a.carotid_radius = rng.uniform(2.7, 3.2);
  a.iac_radius = rng.uniform(2.4, 3.0);
  a.cochlea_radius = rng.uniform(3.0, 3.4);
  a.canal_radius = rng.uniform(0.55, 0.7);
  a.ossicle_scale = rng.uniform(1.05, 1.25);
  a.tmj_scale = rng.uniform(0.9, 1.1);
  a.air_cells = rng.uniform(150, 320);
  a.air_cell_max_radius = rng.uniform(2.0, 3.0);
  a.eac_shift = V3(rng.uniform(-1, 1), rng.uniform(-1, 1), 0);
  a.sinus_shift = V3(rng.uniform(-2, 2), 0, rng.uniform(-1.5, 1.5));
  a.facial_shift = V3(rng.uniform(-1, 1), 0, rng.uniform(-0.8, 0.8));
  a.labyrinth_shift = rng.jitter(0.6);
  a.carotid_shift = rng.jitter(1.0);
  return a;
}

class Painter {
 public:
  // Structures are never thinner than a voxel's half-diagonal (0.87 voxel), so that each holds
  // a voxel centre, and every structure is present, at any resolution.
  Painter(VolumeData& v, bool mirror)
      : v_(v),
        labels_(static_cast<std::uint8_t*>(v.label_data())),
        mirror_(mirror),
        min_radius_(0.87 * kSizeMm / v.shape()[0]) {}

  // Sets `label` where inside(p) holds and allowed(old label) holds, over the box [lo, hi] (mm).
  void paint(V3 lo, V3 hi, const std::function<bool(const V3&)>& inside, std::uint8_t label,
             const std::function<bool(std::uint8_t)>& allowed = nullptr) {
    int a[3], b[3];
    voxel_box(lo, hi, a, b);
    const std::int64_t voxels = std::int64_t(std::max(0, b[0] - a[0])) * std::max(0, b[1] - a[1]) *
                                std::max(0, b[2] - a[2]);
    parallel_slabs(a[2], b[2], voxels, [&](int k0, int k1) {
      for (int k = k0; k < k1; ++k) {
        for (int j = a[1]; j < b[1]; ++j) {
          for (int i = a[0]; i < b[0]; ++i) {
            std::uint8_t& l = labels_[v_.linear_index(i, j, k)];
            if (allowed && !allowed(l)) continue;
            if (inside(centre_mm(i, j, k))) l = label;
          }
        }
      }
    });
  }

  // Many spheres of one label at once, painted over slabs of the grid in parallel (each slab
  // takes every sphere in turn, so the result does not depend on the split); with `within`,
  // only where within(p) holds.
  void spheres(const std::vector<V3>& centres, const std::vector<double>& radii, std::uint8_t label,
               const std::function<bool(const V3&)>& within,
               const std::function<bool(std::uint8_t)>& allowed) {
    std::vector<std::array<int, 6>> boxes(centres.size());
    int k_lo = v_.shape()[2], k_hi = 0;
    for (std::size_t s = 0; s < centres.size(); ++s) {
      int a[3], b[3];
      voxel_box(centres[s].array() - radii[s], centres[s].array() + radii[s], a, b);
      boxes[s] = {a[0], a[1], a[2], b[0], b[1], b[2]};
      k_lo = std::min(k_lo, a[2]);
      k_hi = std::max(k_hi, b[2]);
    }
    parallel_slabs(k_lo, k_hi, std::int64_t(1) << 30, [&](int k0, int k1) {
      for (std::size_t s = 0; s < centres.size(); ++s) {
        const auto& box = boxes[s];
        const double r2 = radii[s] * radii[s];
        for (int k = std::max(k0, box[2]); k < std::min(k1, box[5]); ++k) {
          for (int j = box[1]; j < box[4]; ++j) {
            for (int i = box[0]; i < box[3]; ++i) {
              std::uint8_t& l = labels_[v_.linear_index(i, j, k)];
              if (!allowed(l)) continue;
              const V3 p = centre_mm(i, j, k);
              if ((p - centres[s]).squaredNorm() <= r2 && within(p)) l = label;
            }
          }
        }
      }
    });
  }

  // A tube along a polyline; with `within`, only where within(p) holds.
  void tube(const std::vector<V3>& pts, double r, std::uint8_t label,
            const std::function<bool(const V3&)>& within = nullptr,
            const std::function<bool(std::uint8_t)>& allowed = nullptr) {
    r = std::max(r, min_radius_);
    // The union of one capsule per segment, each over its own box.
    for (std::size_t s = 0; s + 1 < pts.size(); ++s) {
      const V3 &a = pts[s], &b = pts[s + 1];
      paint(
          a.cwiseMin(b).array() - r, a.cwiseMax(b).array() + r,
          [&](const V3& p) { return segment_distance(p, a, b) <= r && (!within || within(p)); },
          label, allowed);
    }
  }

  // A tapered tube: a point is inside where its distance to segment [a, b] is within the radius
  // at its foot, from ra at a to rb at b.
  void taper(const V3& a, const V3& b, double ra, double rb, std::uint8_t label,
             const std::function<bool(std::uint8_t)>& allowed = nullptr) {
    ra = std::max(ra, min_radius_);
    rb = std::max(rb, min_radius_);
    const double r = std::max(ra, rb);
    const V3 ab = b - a;
    paint(
        a.cwiseMin(b).array() - r, a.cwiseMax(b).array() + r,
        [&](const V3& p) {
          const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
          return (p - (a + t * ab)).norm() <= ra + (rb - ra) * t;
        },
        label, allowed);
  }

  void torus(const V3& centre, const V3& axis, double major, double minor, std::uint8_t label) {
    minor = std::max(minor, min_radius_);
    const double reach = major + minor;
    paint(
        centre.array() - reach, centre.array() + reach,
        [&](const V3& p) { return torus_distance(p, centre, axis, major) <= minor; }, label);
  }

  // An axis-aligned ellipsoid.
  void ellipsoid(const V3& c, V3 radii, std::uint8_t label,
                 const std::function<bool(std::uint8_t)>& allowed = nullptr) {
    radii = radii.cwiseMax(min_radius_);
    paint(
        c - radii, c + radii,
        [&](const V3& p) { return (p - c).cwiseQuotient(radii).squaredNorm() <= 1.0; }, label,
        allowed);
  }

  void sphere(const V3& c, double r, std::uint8_t label,
              const std::function<bool(std::uint8_t)>& allowed = nullptr) {
    ellipsoid(c, V3::Constant(r), label, allowed);
  }

  // The phantom-frame point (mm) at voxel (i, j, k)'s centre.
  V3 centre_mm(int i, int j, int k) const {
    const auto& n = v_.shape();
    const double x = (i + 0.5) * kSizeMm / n[0] - kSizeMm / 2;
    return V3(mirror_ ? -x : x, (j + 0.5) * kSizeMm / n[1] - kSizeMm / 2,
              (k + 0.5) * kSizeMm / n[2] - kSizeMm / 2);
  }

 private:
  // The voxel index range [a, b) covering the box [lo, hi] (mm, mirrored for a left ear).
  void voxel_box(V3 lo, V3 hi, int a[3], int b[3]) const {
    if (mirror_) {
      const double x = lo.x();
      lo.x() = -hi.x();
      hi.x() = -x;
    }
    const auto& n = v_.shape();
    for (int ax = 0; ax < 3; ++ax) {
      const double scale = n[ax] / kSizeMm;
      a[ax] = std::clamp(static_cast<int>(std::floor((lo[ax] + kSizeMm / 2) * scale)), 0, n[ax]);
      b[ax] = std::clamp(static_cast<int>(std::ceil((hi[ax] + kSizeMm / 2) * scale)) + 1, 0, n[ax]);
    }
  }

  VolumeData& v_;
  std::uint8_t* labels_;
  bool mirror_;
  double min_radius_;
};

auto only(std::uint8_t label) {
  return [label](std::uint8_t l) { return l == label; };
}

auto any_of(std::initializer_list<std::uint8_t> labels) {
  std::vector<std::uint8_t> v(labels);
  return [v](std::uint8_t l) { return std::find(v.begin(), v.end(), l) != v.end(); };
}

// The skull and the fossae: a rounded block of bone whose lateral face (z = +14 mm, rippled, with
// a fine grain near the surface as a segmented CT has) is where drilling starts; the middle
// cranial fossa above the tegmen and the posterior fossa behind the petrous bone are hollow
// (the brain is not labelled), lined with a layer of dura.
class Skull {
 public:
  Skull(SplitMix& rng, const Anatomy& a, std::uint32_t seed) : a_(a), seed_(seed) {
    double amplitudes = 0;
    for (int w = 0; w < 6; ++w) {
      const V3 dir = V3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)).normalized();
      waves_.push_back(
          {dir * rng.uniform(0.15, 0.45), rng.uniform(0, 6.283), rng.uniform(0.01, 0.02)});
      amplitudes += waves_.back().amplitude;
    }
    ripple_lo_ = 1.0 - amplitudes;
    ripple_hi_ = 1.0 + amplitudes;
    // The brain's lower surface lies a dura's thickness above the tegmen, its lateral surface a
    // dura's thickness medial to z = 8.5 mm (under a thick squama).
    middle_fossa_c_ = V3(2, a.tegmen_height + a.dura_thickness + kMiddleFossaRadii.y(),
                         8.5 - a.dura_thickness - kMiddleFossaRadii.z());
    posterior_fossa_c_ = V3(-24, -4, -41) + a.sinus_shift;
    petrous_origin_ = V3(6, 0, -11) + a.labyrinth_shift;
  }

  // Whether p lies within the skull's outer surface with the block grown by `grow`. The surface
  // is a rounded box whose radii the ripple scales: x^4 + y^4 + z^4 <= ripple^4 in units of the
  // radii; the ripple (six sines) is evaluated only where its bounds leave the answer open.
  bool within(const V3& p, double grow = 1.0) const {
    const double f = superellipsoid(p, kOuterCentre, kOuterRadii * grow);
    if (f <= std::pow(ripple_lo_, 4)) return true;
    if (f > std::pow(ripple_hi_, 4)) return false;
    return f <= std::pow(ripple(p), 4);
  }

  // Fills the whole grid: bone, dura, or empty.
  void fill(VolumeData& volume, bool mirror) const {
    const int n = volume.shape()[0];
    const double step = kSizeMm / n;
    std::vector<double> coord(n), x_of(n);
    for (int i = 0; i < n; ++i) {
      coord[i] = (i + 0.5) * step - kSizeMm / 2;
      x_of[i] = mirror ? -coord[i] : coord[i];
    }
    // The rounded boxes' and spheres' terms are sums of one term per axis.
    auto fourth = [](double v) { return v * v * v * v; };
    std::vector<double> ox(n), oy(n), oz(n), mx(n), my(n), mz(n), px(n), py(n), pz(n);
    for (int i = 0; i < n; ++i) {
      ox[i] = fourth((x_of[i] - kOuterCentre.x()) / kOuterRadii.x());
      oy[i] = fourth((coord[i] - kOuterCentre.y()) / kOuterRadii.y());
      oz[i] = fourth((coord[i] - kOuterCentre.z()) / kOuterRadii.z());
      mx[i] = fourth((x_of[i] - middle_fossa_c_.x()) / kMiddleFossaRadii.x());
      my[i] = fourth((coord[i] - middle_fossa_c_.y()) / kMiddleFossaRadii.y());
      mz[i] = fourth((coord[i] - middle_fossa_c_.z()) / kMiddleFossaRadii.z());
      px[i] = std::pow(x_of[i] - posterior_fossa_c_.x(), 2);
      py[i] = std::pow(coord[i] - posterior_fossa_c_.y(), 2);
      pz[i] = std::pow(coord[i] - posterior_fossa_c_.z(), 2);
    }
    // Inside the brain, and inside the brain grown by the dura, as thresholds on those sums.
    const double t = a_.dura_thickness;
    const double middle_in = 1.0, middle_dura = fourth(1.0 + t / kMiddleFossaRadii.y());
    const double posterior_in = kPosteriorFossaRadius * kPosteriorFossaRadius;
    const double posterior_dura = std::pow(kPosteriorFossaRadius + t, 2);
    constexpr double kRoughness = 0.035;
    const double sure_in = std::pow(ripple_lo_, 4) * (1 - kRoughness);
    const double sure_out = std::pow(ripple_hi_, 4) * (1 + kRoughness);
    // sin(kx x + ky y + kz z + phase) from per-axis complex exponentials: the x factor per
    // voxel times the y and z factors per row.
    const std::size_t nw = waves_.size();
    std::vector<std::complex<double>> ex(nw * n), ey(nw * n), ez(nw * n);
    for (std::size_t w = 0; w < nw; ++w) {
      for (int i = 0; i < n; ++i) {
        ex[w * n + i] = std::polar(1.0, waves_[w].k.x() * x_of[i] + waves_[w].phase);
        ey[w * n + i] = std::polar(1.0, waves_[w].k.y() * coord[i]);
        ez[w * n + i] = std::polar(1.0, waves_[w].k.z() * coord[i]);
      }
    }
    auto* labels = static_cast<std::uint8_t*>(volume.label_data());
    parallel_slabs(0, n, std::int64_t(n) * n * n, [&](int k0, int k1) {
      std::vector<double> row_re(nw), row_im(nw);
      for (int k = k0; k < k1; ++k) {
        for (int j = 0; j < n; ++j) {
          for (std::size_t w = 0; w < nw; ++w) {
            // Written out: std::complex's operator* checks for NaNs.
            const auto &b = ey[w * n + j], &c = ez[w * n + k];
            row_re[w] = b.real() * c.real() - b.imag() * c.imag();
            row_im[w] = b.real() * c.imag() + b.imag() * c.real();
          }
          for (int i = 0; i < n; ++i) {
            const double f = ox[i] + oy[j] + oz[k];
            if (f > sure_out) continue;
            const V3 p(x_of[i], coord[j], coord[k]);
            if (f > sure_in) {
              // Near the surface: the ripple, and a fine grain within a band around it.
              double ripple = 1.0;
              for (std::size_t w = 0; w < nw; ++w) {
                const auto& a = ex[w * n + i];
                ripple += waves_[w].amplitude * (a.real() * row_im[w] + a.imag() * row_re[w]);
              }
              const double r2 = ripple * ripple;
              const double g = f / (r2 * r2);
              const bool in = std::abs(g - 1.0) > kRoughness
                                  ? g <= 1.0
                                  : g <= 1.0 + kRoughness * value_noise(p / 1.1, seed_);
              if (!in) continue;
            }
            const double m = mx[i] + my[j] + mz[k], q = px[i] + py[j] + pz[k];
            std::uint8_t& l = labels[volume.linear_index(i, j, k)];
            if (m < middle_in || q < posterior_in) {
              l = kEmpty;
            } else if (m < middle_dura || q < posterior_dura) {
              l = kSinusDura;
            } else {
              l = beyond(p) ? kEmpty : kBone;
            }
          }
        }
      }
    });
  }

 private:
  struct Wave {
    V3 k;
    double phase, amplitude;
  };

  double ripple(const V3& p) const {
    double r = 1.0;
    for (const Wave& w : waves_) r += w.amplitude * std::sin(w.k.dot(p) + w.phase);
    return r;
  }

  // Outside the temporal bone though inside the block: the neck and infratemporal space below
  // the mastoid and the tympanic bone, and whatever lies medially off the petrous pyramid (a
  // cylinder around its axis, through the vestibule towards the apex).
  bool beyond(const V3& p) const {
    if ((p - kNeckCentre).cwiseQuotient(kNeckRadii).squaredNorm() <= 1.0) return true;
    if (p.z() >= kPetrousFrom) return false;
    const V3 d = p - petrous_origin_;
    const double along = d.dot(kPetrousAxis);
    return d.squaredNorm() - along * along > kPetrousRadius * kPetrousRadius;
  }

  inline static const V3 kOuterCentre{0, 0, -4};
  inline static const V3 kOuterRadii{26, 26, 18};
  inline static const V3 kMiddleFossaRadii{30, 16, 16};
  static constexpr double kPosteriorFossaRadius = 30.0;
  inline static const V3 kNeckCentre{10, -34, -20};
  inline static const V3 kNeckRadii{24, 22, 26};
  inline static const V3 kPetrousAxis = V3(0.6, -0.1, -0.8).normalized();
  static constexpr double kPetrousFrom = -6.0;
  static constexpr double kPetrousRadius = 9.0;

  const Anatomy& a_;
  std::uint32_t seed_;
  std::vector<Wave> waves_;
  double ripple_lo_, ripple_hi_;
  V3 middle_fossa_c_, posterior_fossa_c_, petrous_origin_;
};

// The landmarks every structure is placed from (mm, phantom frame).
struct Landmarks {
  V3 eac;        // centre of the canal's lumen, half way along it
  V3 antrum;     // the mastoid antrum
  V3 vestibule;  // centre of the vestibule
  V3 fundus;     // lateral end of the internal auditory canal
};

Landmarks place_landmarks(const Anatomy& a) {
  Landmarks m;
  m.eac = V3(7, -1, 6) + a.eac_shift;
  m.antrum = V3(1.5, 5.0, -1.5);
  m.vestibule = V3(6, 1.5, -11) + a.labyrinth_shift;
  m.fundus = m.vestibule + V3(1.5, -1.5, -2.0);
  return m;
}

// Mastoid cortex details: the mastoid tip below and behind the canal, the zygomatic root in front
// of and above it, and the suprameatal (Henle's) spine at its posterosuperior rim.
void paint_cortex(Painter& paint, const Landmarks& m, const Anatomy& a) {
  paint.ellipsoid(V3(-6, -18, 6), V3(8, 8, 7.5), kBone, only(kEmpty));
  // The zygomatic root: a ridge that rises out of the squama above the canal and runs forwards.
  const V3 root = m.eac + V3(3, 6, 7.6);
  paint.taper(m.eac + V3(-9, 6.5, 6.8), root, 1.0, 2.6, kBone, only(kEmpty));
  paint.tube({root, m.eac + V3(10, 6.5, 7.5), V3(24, m.eac.y() + 6, 13)}, 2.6, kBone, nullptr,
             only(kEmpty));
  const V3 rim = m.eac + V3(2.0 - a.eac_radius * 0.75, 1.0 + a.eac_radius * 0.65, 8.2);
  paint.tube({rim, rim + V3(0.4, -0.3, 1.2)}, 0.7, kBone, nullptr, only(kEmpty));
}

// Pneumatisation: the antrum and a seeded number of air cells in the mastoid, behind the canal
// and below the tegmen, under an outer cortex about 3 mm thick.
void paint_air_cells(Painter& paint, const Skull& skull, SplitMix& rng, const Landmarks& m,
                     const Anatomy& a) {
  paint.sphere(m.antrum, 2.8, kEmpty, only(kBone));
  const int cells = static_cast<int>(a.air_cells);
  std::vector<V3> centres;
  std::vector<double> radii;
  for (int c = 0; c < cells; ++c) {
    centres.emplace_back(rng.uniform(-22, 3), rng.uniform(-22, a.tegmen_height - 2),
                         rng.uniform(-4, 13));
    radii.push_back(rng.uniform(0.7, a.air_cell_max_radius));
  }
  paint.spheres(
      centres, radii, kEmpty, [&](const V3& p) { return skull.within(p, 0.84); }, only(kBone));
}

// External auditory canal from the tympanic membrane out to the lateral surface, and the
// temporomandibular joint in front of it.
void paint_canal_and_joint(Painter& paint, const Skull& skull, const Landmarks& m,
                           const Anatomy& a) {
  const double s = a.tmj_scale;
  paint.ellipsoid(m.eac + V3(13.5, 0, 0), V3(4.5, 7, 6.5) * s, kTmj, any_of({kBone, kEmpty}));
  // In front of the canal the cortex falls away to the joint: the condyle shows in its fossa.
  paint.ellipsoid(m.eac + V3(15, -2, 9), V3(6.5, 8, 4.5), kEmpty, only(kBone));
  // The lateral (cartilaginous) part turns forwards to its opening.
  const std::vector<V3> canal = {m.eac + V3(1.5, 0.5, -7), m.eac + V3(0.5, 0, -3),
                                 m.eac + V3(1.5, 0.4, 4), m.eac + V3(2.0, 1.0, 12)};
  paint.tube(canal, a.eac_radius, kEac, [&](const V3& p) { return skull.within(p, 1.01); });
}

// Middle ear: an air-filled cavity medial to the tympanic membrane holding the ossicles.
void paint_middle_ear(Painter& paint, const Landmarks& m, const Anatomy& a) {
  const V3 c = m.eac + V3(0.5, 3.5, -12.5);
  paint.ellipsoid(c, V3(4.5, 5.2, 2.2), kEmpty, any_of({kBone, kSinusDura}));
  paint.tube({c, m.antrum}, 1.6, kEmpty, nullptr, only(kBone));  // the aditus
  const double s = a.ossicle_scale;
  const V3 malleus = c + V3(1.0, 2.3, 1.0);
  paint.sphere(malleus, 1.0 * s, kMalleus);
  paint.tube({malleus, malleus + V3(0.3, -4.2, 0.5)}, 0.5 * s, kMalleus);
  const V3 incus = c + V3(-0.9, 2.1, 0.1);
  paint.sphere(incus, 1.1 * s, kIncus);
  paint.tube({incus, incus + V3(-1.8, 0.3, 0)}, 0.6 * s, kIncus);
  const V3 lenticular = incus + V3(0, -4.1, -0.8);
  paint.tube({incus, lenticular}, 0.5 * s, kIncus);
  const V3 footplate = m.vestibule + V3(0.3, -0.5, 1.7);
  paint.tube({lenticular, footplate}, 0.35 * s, kStapes);
  paint.ellipsoid(footplate, V3(1.3, 0.6, 0.3) * s, kStapes);
}

// Sigmoid sinus in its groove behind the mastoid, down to the jugular bulb; the dura lines the
// fossae already.
void paint_sinus(Painter& paint, const Skull& skull, const Anatomy& a) {
  const V3 d = a.sinus_shift;
  paint.tube(
      {V3(-24, 9, -3) + d, V3(-16, 5, 0) + d, V3(-11, -3, 0) + d, V3(-9, -11, -3.5) + d,
       V3(-3, -17, -9) + d, V3(3, -18, -13) + d},
      a.sinus_radius, kSinusDura, [&](const V3& p) { return skull.within(p); },
      any_of({kBone, kEmpty}));
}

// Internal carotid artery: its vertical segment rising below the cochlea, the genu, then the
// horizontal segment running anteromedially.
void paint_carotid(Painter& paint, const Landmarks& m, const Anatomy& a) {
  const V3 c = m.vestibule + a.carotid_shift;
  paint.tube(
      {c + V3(8.5, -14, 1), c + V3(9, -7, -0.5), c + V3(11, -4.5, -4), c + V3(15.5, -3.5, -11)},
      a.carotid_radius, kCarotid);
}

// Bony labyrinth (vestibule, the three semicircular canals, the cochlea), the vestibular
// aqueduct, and the internal auditory canal with its nerves.
void paint_inner_ear(Painter& paint, const Landmarks& m, const Anatomy& a) {
  const V3 v = m.vestibule;
  const V3 iac_axis = V3(-0.1, -0.05, -1).normalized();
  paint.tube({m.fundus, m.fundus + 10.0 * iac_axis}, a.iac_radius, kIac);
  paint.ellipsoid(v, V3(2.4, 1.8, 1.8), kLabyrinth);
  const double r = a.canal_radius;
  paint.torus(v + V3(-3.3, 0.8, 0.6), V3(0, 1, 0.35), 3.1, r, kLabyrinth);   // lateral
  paint.torus(v + V3(-0.5, 3.6, -1.2), V3(1, 0, -0.9), 3.2, r, kLabyrinth);  // superior
  paint.torus(v + V3(-3.2, 0.8, -2.8), V3(1, 0.1, 1), 3.1, r, kLabyrinth);   // posterior
  const V3 cochlea = v + V3(4.5, -1.5, -1.5);
  const V3 cochlea_axis = V3(1, -0.2, -0.5).normalized();
  const double turns[3][2] = {{1.0, 0.85}, {0.62, 0.7}, {0.3, 0.55}};
  for (int t = 0; t < 3; ++t) {
    paint.torus(cochlea + cochlea_axis * (0.9 * t), cochlea_axis,
                (a.cochlea_radius - 0.85) * turns[t][0], turns[t][1], kLabyrinth);
  }
  paint.tube({v + V3(-1.5, -1.0, -0.8), v + V3(-6.5, -4.5, 2.5)}, 0.4, kVestibularAqueduct);
  // The nerves leave the fundus for the vestibule (superior and inferior vestibular) and the
  // cochlea.
  paint.tube({m.fundus + V3(-0.8, 0.8, -1.2), v + V3(0.3, 1.6, -0.8)}, 0.32,
             kSuperiorVestibularNerve);
  paint.tube({m.fundus + V3(-0.6, -1.3, -0.4), v + V3(-0.6, -1.9, -0.6)}, 0.27,
             kInferiorVestibularNerve);
  paint.tube({m.fundus + V3(0.6, -0.8, -2.5), cochlea + V3(-0.8, 0.2, 0.2)}, 0.5, kCochlearNerve);
}

// Facial nerve (labyrinthine and tympanic segments, second genu, mastoid segment down to the
// stylomastoid foramen) and the chorda tympani leaving it anterolaterally, which leaves the
// facial recess between them, and crossing the middle ear.
void paint_facial_nerve(Painter& paint, const Landmarks& m, const Anatomy& a) {
  const V3 v = m.vestibule;
  const V3 d = a.facial_shift;
  const V3 genu = v + V3(-3.0, 0.0, 5.5) + d;
  const std::vector<V3> facial = {
      m.fundus + V3(0.5, 1.0, 0), v + V3(4.5, 2.0, 1.0),         // labyrinthine, to the geniculum
      v + V3(1.5, 1.5, 3.2),      genu,                          // tympanic
      genu + V3(-0.3, -6, 1.5),   genu + V3(-0.5, -14.5, 3.0)};  // mastoid
  paint.tube(facial, a.facial_radius, kFacialNerve);
  const V3 branch = genu + V3(-0.3, -9, 2.2);
  paint.tube({branch, branch + V3(2.5, 4.5, 1.5), m.eac + V3(1.5, 3.5, -11.8),
              m.eac + V3(7, 1.5, -14), m.eac + V3(13, -2, -17)},
             0.35, kChordaTympani);
}

}  // namespace

LabelTable phantom_label_table() {
  // Removable and critical as the drilling and the metrics need them; names, ids and colours as
  // the original system's labels.csv gives them.
  return LabelTable({
      {kBone, "Bone", {255, 249, 219}, true, false},
      {kMalleus, "Malleus", {233, 0, 255}, false, false},
      {kIncus, "Incus", {0, 255, 149}, false, false},
      {kStapes, "Stapes", {63, 0, 255}, false, false},
      {kLabyrinth, "Bony_Labyrinth", {91, 123, 91}, true, true},
      {kIac, "IAC", {244, 142, 52}, true, true},
      {kSuperiorVestibularNerve, "Superior_Vestibular_Nerve", {255, 191, 135}, true, true},
      {kInferiorVestibularNerve, "Inferior_Vestibular_Nerve", {121, 70, 24}, true, true},
      {kCochlearNerve, "Cochlear_Nerve", {219, 244, 52}, true, true},
      {kFacialNerve, "Facial_Nerve", {244, 214, 49}, true, true},
      {kChordaTympani, "Chorda_Tympani", {151, 131, 29}, true, true},
      {kCarotid, "ICA", {216, 100, 79}, true, true},
      {kSinusDura, "Sinus_+_Dura", {110, 184, 209}, true, true},
      {kVestibularAqueduct, "Vestibular_Aqueduct", {91, 98, 123}, true, true},
      {kTmj, "TMJ", {100, 0, 0}, false, false},
      {kEac, "EAC", {255, 225, 214}, false, false},
  });
}

PhantomSide parse_phantom_side(const std::string& side) {
  if (side == "right") return PhantomSide::kRight;
  if (side == "left") return PhantomSide::kLeft;
  throw ArgumentError("phantom side must be \"right\" or \"left\", got \"" + side + "\"");
}

std::shared_ptr<VolumeData> make_temporal_bone_phantom(int resolution, std::uint32_t seed,
                                                       PhantomSide side) {
  if (resolution < 16 || resolution > 2048) {
    throw ArgumentError("phantom resolution must be 16..2048 voxels, got " +
                        std::to_string(resolution));
  }
  if (side != PhantomSide::kRight && side != PhantomSide::kLeft) {
    throw ArgumentError("phantom side must be right or left");
  }
  const bool left = side == PhantomSide::kLeft;
  auto volume = std::make_shared<VolumeData>(std::array<int, 3>{resolution, resolution, resolution},
                                             V3::Constant(kSizeMm / 1000.0), LabelType::kUInt8,
                                             phantom_label_table());
  SplitMix rng(0x5eed0000ull + seed);
  const Anatomy anatomy = sample_anatomy(rng);
  const Landmarks marks = place_landmarks(anatomy);
  const Skull skull(rng, anatomy, seed);
  skull.fill(*volume, left);

  Painter paint(*volume, left);
  paint_cortex(paint, marks, anatomy);
  paint_air_cells(paint, skull, rng, marks, anatomy);
  paint_canal_and_joint(paint, skull, marks, anatomy);
  paint_sinus(paint, skull, anatomy);
  paint_middle_ear(paint, marks, anatomy);
  paint_carotid(paint, marks, anatomy);
  paint_inner_ear(paint, marks, anatomy);
  paint_facial_nerve(paint, marks, anatomy);

  volume->commit();
  volume->set_source("phantom(resolution=" + std::to_string(resolution) + ", seed=" +
                     std::to_string(seed) + ", side=" + (left ? "left" : "right") + ")");
  return volume;
}

}  // namespace ambfplus
