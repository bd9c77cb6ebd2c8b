#pragma once

#include <array>
#include <vector>

#include <Eigen/Geometry>

#include "ambfplus/export.h"
#include "ambfplus/io/mesh.h"

namespace ambfplus {

/// Where a sphere swept along a segment first touches a triangle mesh.
struct AMBFPLUS_API MeshHit {
  bool hit = false;
  double t = 1.0;  ///< fraction of the segment travelled before contact, 0..1
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< from the touched point to the sphere
};

/// Swept-sphere queries against rigid parts (the bodies a tool can meet besides the anatomy):
/// triangle meshes and infinite planes, each with its own pose, so a moving part costs a pose
/// update, not a rebuild. Exact: a moving sphere meets a triangle on its face, along an edge or at
/// a corner, whichever comes first. Triangles are grouped with a bounding box each and every part
/// has a bounding sphere, so a query opens only what is near the sweep.
class AMBFPLUS_API MeshCollider {
 public:
  /// Adds a part made of the mesh's triangles (in the part's frame); returns its index.
  int add_mesh(const MeshData& mesh);
  /// Adds the part's plane z = 0, solid below (the side -z); returns its index.
  int add_plane();
  /// Places part i: the query frame from the part's frame.
  void set_pose(int part, const Eigen::Isometry3d& frame_from_part);
  int parts() const { return static_cast<int>(parts_.size()); }
  void clear() { parts_.clear(); }

  /// First contact of a sphere of radius r moving from a to b (query frame). A sphere already
  /// touching something is blocked only if it moves further in.
  MeshHit sweep(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) const;

 private:
  struct Group {
    std::vector<Eigen::Vector3d> v;  // 3 per triangle
    Eigen::Vector3d lo, hi;
  };
  struct Part {
    bool plane = false;
    std::vector<Group> groups;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // bounding sphere, part frame
    double bound = 0.0;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d inverse = Eigen::Isometry3d::Identity();
  };
  // Earliest contact (distance along the unit direction d) with one part, in its frame.
  void sweep_part(const Part& part, const Eigen::Vector3d& a, const Eigen::Vector3d& d,
                  double length, double r, double& best_t, Eigen::Vector3d& best_point) const;

  std::vector<Part> parts_;
};

}  // namespace ambfplus
