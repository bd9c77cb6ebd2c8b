#include "haptics/critical_distances.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ambfplus {
namespace {

// A rebuild's thread runs at normal priority, whatever the thread that started it (a real-time
// loop's SCHED_FIFO thread passes its policy on to threads it creates).
void run_at_normal_priority() {
  sched_param p{};
  pthread_setschedparam(pthread_self(), SCHED_OTHER, &p);
}

}  // namespace

CriticalDistances::CriticalDistances(const VolumeData& data,
                                     const std::vector<std::uint16_t>& labels)
    : data_(data), labels_(labels) {
  const auto& n = data_.shape();
  std::vector<bool> tracked(65536, false);
  for (std::uint16_t l : labels_) {
    tracked[l] = true;
    structures_[l];
  }
  // One pass over the grid for every label. The nearest voxel of a structure to a point outside
  // it is on the structure's boundary, so only boundary voxels are kept.
  std::map<std::uint16_t, std::vector<Point>> boundary;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const std::uint16_t l = data_.label(i, j, k);
        if (l == 0 || !tracked[l]) continue;
        auto same = [&](int a, int b, int c) {
          return a >= 0 && b >= 0 && c >= 0 && a < n[0] && b < n[1] && c < n[2] &&
                 data_.label(a, b, c) == l;
        };
        if (same(i - 1, j, k) && same(i + 1, j, k) && same(i, j - 1, k) && same(i, j + 1, k) &&
            same(i, j, k - 1) && same(i, j, k + 1)) {
          continue;
        }
        boundary[l].push_back({data_.voxel_center(i, j, k), {i, j, k}});
      }
  for (auto& [label, s] : structures_) s.tree = build(std::move(boundary[label]));
}

CriticalDistances::~CriticalDistances() {
  for (auto& [label, s] : structures_) {
    if (s.rebuilding.valid()) s.rebuilding.wait();
    if (s.retiring.valid()) s.retiring.wait();
  }
}

std::shared_ptr<const CriticalDistances::Tree> CriticalDistances::build(std::vector<Point> points) {
  auto tree = std::make_shared<Tree>();
  tree->points = std::move(points);
  tree->axis.assign(tree->points.size(), 0);
  tree->box_lo.assign(tree->points.size(), Eigen::Vector3d::Zero());
  tree->box_hi.assign(tree->points.size(), Eigen::Vector3d::Zero());
  build(*tree, 0, tree->points.size());
  return tree;
}

void CriticalDistances::collect(Structure& s) {
  if (!s.rebuilding.valid() ||
      s.rebuilding.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    return;
  }
  std::shared_ptr<const Tree> old = std::move(s.tree);
  s.tree = s.rebuilding.get();
  // The old tree is freed on another thread: its pages going back cost milliseconds.
  if (s.retiring.valid()) s.retiring.wait();
  s.retiring = std::async(std::launch::async, [old = std::move(old)]() mutable {
    run_at_normal_priority();
    old.reset();
  });
  s.added.erase(s.added.begin(), s.added.begin() + static_cast<std::ptrdiff_t>(s.folding));
  s.folding = 0;
  ++rebuilds_;
}

void CriticalDistances::build(Tree& tree, std::size_t lo, std::size_t hi) {
  if (hi <= lo) return;
  Eigen::Vector3d a = tree.points[lo].p, b = a;
  for (std::size_t i = lo; i < hi; ++i) {
    a = a.cwiseMin(tree.points[i].p);
    b = b.cwiseMax(tree.points[i].p);
  }
  const std::size_t mid = lo + (hi - lo) / 2;
  if (hi - lo == 1) {
    tree.box_lo[mid] = a;
    tree.box_hi[mid] = b;
    return;
  }
  int axis = 0;
  (b - a).maxCoeff(&axis);
  std::nth_element(tree.points.begin() + lo, tree.points.begin() + mid, tree.points.begin() + hi,
                   [axis](const Point& x, const Point& y) {
                     return x.p[axis] < y.p[axis] || (x.p[axis] == y.p[axis] && x.voxel < y.voxel);
                   });
  tree.axis[mid] = static_cast<std::uint8_t>(axis);
  tree.box_lo[mid] = a;
  tree.box_hi[mid] = b;
  build(tree, lo, mid);
  build(tree, mid + 1, hi);
}

void CriticalDistances::search(const Tree& tree, std::size_t lo, std::size_t hi,
                               const Eigen::Vector3d& p, std::uint16_t label, double& best) const {
  if (lo >= hi) return;
  const std::size_t mid = lo + (hi - lo) / 2;
  // Nothing in this node's box can be nearer than the best so far.
  const Eigen::Vector3d gap = (tree.box_lo[mid] - p).cwiseMax(p - tree.box_hi[mid]).cwiseMax(0.0);
  if (gap.squaredNorm() >= best * best) return;
  const Point& q = tree.points[mid];
  const double d2 = (q.p - p).squaredNorm();
  if (d2 < best * best && alive(q, label)) best = std::sqrt(d2);
  if (hi - lo == 1) return;
  const int axis = tree.axis[mid];
  const double diff = p[axis] - q.p[axis];
  // The side of the split holding p first: it likely holds the nearest, and the best it gives
  // prunes the other side by its box.
  if (diff < 0) {
    search(tree, lo, mid, p, label, best);
    search(tree, mid + 1, hi, p, label, best);
  } else {
    search(tree, mid + 1, hi, p, label, best);
    search(tree, lo, mid, p, label, best);
  }
}

void CriticalDistances::removed(const std::array<int, 3>& v, std::uint16_t label) {
  auto it = structures_.find(label);
  if (it == structures_.end()) return;
  Structure& s = it->second;
  const auto& n = data_.shape();
  const int offsets[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  for (const auto& o : offsets) {
    const std::array<int, 3> w = {v[0] + o[0], v[1] + o[1], v[2] + o[2]};
    if (w[0] < 0 || w[1] < 0 || w[2] < 0 || w[0] >= n[0] || w[1] >= n[1] || w[2] >= n[2]) continue;
    if (data_.label(w[0], w[1], w[2]) == label) {
      s.added.push_back({data_.voxel_center(w[0], w[1], w[2]), w});
    }
  }
  collect(s);
  if (s.rebuilding.valid() || s.added.size() <= kRebuildAfter) return;
  // The old tree is shared, not copied: this thread only copies the short list.
  s.folding = s.added.size();
  std::shared_ptr<const Tree> old = s.tree;
  std::vector<Point> added(s.added.begin(), s.added.end());
  s.rebuilding = std::async(std::launch::async, [old, added = std::move(added)]() {
    run_at_normal_priority();
    std::vector<Point> all;
    all.reserve(old->points.size() + added.size());
    all.insert(all.end(), old->points.begin(), old->points.end());
    all.insert(all.end(), added.begin(), added.end());
    return build(std::move(all));
  });
}

double CriticalDistances::distance(const Eigen::Vector3d& p, std::uint16_t label) {
  Structure& s = structures_[label];
  collect(s);
  double best = std::numeric_limits<double>::infinity();
  for (const Point& q : s.added) {
    const double d = (q.p - p).norm();
    if (d < best && alive(q, label)) best = d;
  }
  if (s.tree) search(*s.tree, 0, s.tree->points.size(), p, label, best);
  return best;
}

}  // namespace ambfplus
