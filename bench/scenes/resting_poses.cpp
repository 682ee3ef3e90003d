#include "scenes/resting_poses.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <utility>

#include "core/error.h"

namespace ecv::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<Eigen::Vector3d> Vertices(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> vertices;
  vertices.reserve(mesh.NumVertices());
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3f& p : part.positions) vertices.push_back(p.cast<double>());
  }
  return vertices;
}

// Centre of mass of the enclosed volume (sum of signed tetrahedra from the origin) for closed meshes, else of the
// vertices.
Eigen::Vector3d CentreOfMass(const TriangleMesh& mesh, const std::vector<Eigen::Vector3d>& vertices) {
  if (mesh.IsClosedOutward()) {
    double volume6 = 0.0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (const MeshPart& part : mesh.parts) {
      for (const Eigen::Vector3i& t : part.triangles) {
        const Eigen::Vector3d a = part.positions[static_cast<size_t>(t.x())].cast<double>();
        const Eigen::Vector3d b = part.positions[static_cast<size_t>(t.y())].cast<double>();
        const Eigen::Vector3d c = part.positions[static_cast<size_t>(t.z())].cast<double>();
        const double v6 = a.dot(b.cross(c));
        volume6 += v6;
        moment += v6 * (a + b + c) / 4.0;
      }
    }
    if (volume6 > 0.0) return moment / volume6;
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : vertices) sum += v;
  return sum / static_cast<double>(vertices.size());
}

// Convex hull of 2D points (Andrew's monotone chain), counter-clockwise, without collinear points.
std::vector<Eigen::Vector2d> ConvexHull2d(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

double PolygonArea(const std::vector<Eigen::Vector2d>& polygon) {
  double twice = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * twice;
}

// Distance of `point` inside the counter-clockwise convex `polygon` from its nearest edge; negative outside.
double InsideMargin(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& point) {
  if (polygon.size() < 3) return -1.0;
  double margin = 1e30;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d edge = polygon[(i + 1) % polygon.size()] - polygon[i];
    const Eigen::Vector2d inward(-edge.y(), edge.x());
    margin = std::min(margin, inward.normalized().dot(point - polygon[i]));
  }
  return margin;
}

// Facets of the 3D convex hull (quickhull, Barber et al. 1996): outward unit normal and area each. Points within
// `eps` of a facet's plane count as on it. Empty when the points span no volume.
class ConvexHull3d {
 public:
  struct Facet {
    Eigen::Vector3d normal;
    double area;
  };

  ConvexHull3d(const std::vector<Eigen::Vector3d>& points, double eps) : points_(points), eps_(eps) {}

  std::vector<Facet> Facets() {
    if (!Start()) return {};
    std::vector<int> pending;
    for (size_t f = 0; f < faces_.size(); ++f) pending.push_back(static_cast<int>(f));
    while (!pending.empty()) {
      const int f = pending.back();
      pending.pop_back();
      if (faces_[static_cast<size_t>(f)].alive && !faces_[static_cast<size_t>(f)].outside.empty()) Expand(f, &pending);
    }
    std::vector<Facet> facets;
    for (const Face& face : faces_) {
      if (!face.alive) continue;
      const Eigen::Vector3d cross = (P(face.v[1]) - P(face.v[0])).cross(P(face.v[2]) - P(face.v[0]));
      if (cross.norm() > 0.0) facets.push_back({cross.normalized(), 0.5 * cross.norm()});
    }
    return facets;
  }

 private:
  struct Face {
    int v[3];
    Eigen::Vector3d normal;
    double offset;
    std::vector<int> outside;
    bool alive = true;
  };

  const Eigen::Vector3d& P(int i) const { return points_[static_cast<size_t>(i)]; }
  double Distance(const Face& face, int i) const { return face.normal.dot(P(i)) - face.offset; }
  static uint64_t Key(int a, int b) { return static_cast<uint64_t>(a) << 32 | static_cast<uint32_t>(b); }

  int Farthest(const std::function<double(int)>& score) const {
    int best = 0;
    for (int i = 1; i < static_cast<int>(points_.size()); ++i) {
      if (score(i) > score(best)) best = i;
    }
    return best;
  }

  // A tetrahedron of far-apart points, every other point given to a face it lies outside of.
  bool Start() {
    if (points_.size() < 4) return false;
    const int a = Farthest([&](int i) { return -P(i).x(); });
    const int b = Farthest([&](int i) { return (P(i) - P(a)).squaredNorm(); });
    const Eigen::Vector3d ab = (P(b) - P(a)).normalized();
    const int c = Farthest([&](int i) { return (P(i) - P(a)).cross(ab).squaredNorm(); });
    const Eigen::Vector3d n = ab.cross(P(c) - P(a)).normalized();
    const int d = Farthest([&](int i) { return std::abs(n.dot(P(i) - P(a))); });
    if ((P(b) - P(a)).norm() <= eps_ || (P(c) - P(a)).cross(ab).norm() <= eps_ ||
        std::abs(n.dot(P(d) - P(a))) <= eps_) {
      return false;
    }
    const Eigen::Vector3d centre = (P(a) + P(b) + P(c) + P(d)) / 4.0;
    const int corners[4][3] = {{a, b, c}, {a, b, d}, {a, c, d}, {b, c, d}};
    std::vector<int> created;
    for (const auto& corner : corners) {
      Face face = MakeFace(corner[0], corner[1], corner[2]);
      if (face.normal.dot(centre) - face.offset > 0.0) {
        face = MakeFace(corner[0], corner[2], corner[1]);
      }
      created.push_back(AddFace(std::move(face)));
    }
    std::vector<int> all(points_.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
    Assign(all, created);
    return true;
  }

  Face MakeFace(int a, int b, int c) const {
    Face face{{a, b, c}, Eigen::Vector3d::Zero(), 0.0, {}, true};
    const Eigen::Vector3d cross = (P(b) - P(a)).cross(P(c) - P(a));
    if (cross.norm() > 0.0) face.normal = cross.normalized();
    face.offset = face.normal.dot(P(a));
    return face;
  }

  int AddFace(Face face) {
    const int index = static_cast<int>(faces_.size());
    for (int k = 0; k < 3; ++k) edges_[Key(face.v[k], face.v[(k + 1) % 3])] = index;
    faces_.push_back(std::move(face));
    return index;
  }

  void Assign(const std::vector<int>& points, const std::vector<int>& faces) {
    for (int i : points) {
      for (int f : faces) {
        if (Distance(faces_[static_cast<size_t>(f)], i) > eps_) {
          faces_[static_cast<size_t>(f)].outside.push_back(i);
          break;
        }
      }
    }
  }

  // Adds the farthest outside point of face `f`: removes the faces it sees, closes the horizon with new ones.
  void Expand(int f, std::vector<int>* pending) {
    const Face& start = faces_[static_cast<size_t>(f)];
    const int apex = *std::max_element(start.outside.begin(), start.outside.end(),
                                       [&](int i, int j) { return Distance(start, i) < Distance(start, j); });
    std::vector<int> visible{f}, stack{f};
    std::vector<std::pair<int, int>> horizon;
    std::unordered_map<int, bool> seen{{f, true}};
    while (!stack.empty()) {
      const Face& face = faces_[static_cast<size_t>(stack.back())];
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const int a = face.v[k], b = face.v[(k + 1) % 3];
        const auto across = edges_.find(Key(b, a));
        const int g = across == edges_.end() ? -1 : across->second;
        const bool sees =
            g >= 0 && faces_[static_cast<size_t>(g)].alive && Distance(faces_[static_cast<size_t>(g)], apex) > eps_;
        if (sees && !seen[g]) {
          seen[g] = true;
          visible.push_back(g);
          stack.push_back(g);
        } else if (!sees) {
          horizon.emplace_back(a, b);
        }
      }
    }
    std::vector<int> orphans;
    for (int g : visible) {
      Face& face = faces_[static_cast<size_t>(g)];
      face.alive = false;
      for (int k = 0; k < 3; ++k) {
        const auto edge = edges_.find(Key(face.v[k], face.v[(k + 1) % 3]));
        if (edge != edges_.end() && edge->second == g) edges_.erase(edge);
      }
      for (int i : face.outside) {
        if (i != apex) orphans.push_back(i);
      }
      face.outside.clear();
    }
    std::vector<int> created;
    for (const auto& [a, b] : horizon) created.push_back(AddFace(MakeFace(a, b, apex)));
    Assign(orphans, created);
    pending->insert(pending->end(), created.begin(), created.end());
  }

  const std::vector<Eigen::Vector3d>& points_;
  double eps_;
  std::vector<Face> faces_;
  std::unordered_map<uint64_t, int> edges_;  // directed edge (a, b) -> the face that runs through it so
};

// Outward normals of the hull's facets, facets within `merge_deg` of a larger one merged (area-weighted mean).
std::vector<Eigen::Vector3d> MergedNormals(std::vector<ConvexHull3d::Facet> facets, double merge_deg) {
  std::sort(facets.begin(), facets.end(),
            [](const ConvexHull3d::Facet& a, const ConvexHull3d::Facet& b) { return a.area > b.area; });
  const double merge_cos = std::cos(merge_deg * kPi / 180.0);
  std::vector<Eigen::Vector3d> seeds, sums;
  for (const ConvexHull3d::Facet& facet : facets) {
    size_t k = 0;
    while (k < seeds.size() && seeds[k].dot(facet.normal) < merge_cos) ++k;
    if (k == seeds.size()) {
      seeds.push_back(facet.normal);
      sums.push_back(Eigen::Vector3d::Zero());
    }
    sums[k] += facet.area * facet.normal;
  }
  for (Eigen::Vector3d& sum : sums) sum.normalize();
  return sums;
}

// How the object rests with `down` (unit, object frame) pointing at the table.
struct Support {
  Eigen::Vector3d down;
  double height = 0.0;  // largest vertex coordinate along `down`: the table plane
  double area = 0.0;    // of the support polygon
  double margin = 0.0;  // of the centre of mass's foot inside it
};

Support EvaluateSupport(const std::vector<Eigen::Vector3d>& vertices, const Eigen::Vector3d& centre,
                        const Eigen::Vector3d& down, double contact_tolerance) {
  Support support{down};
  support.height = -1e30;
  for (const Eigen::Vector3d& v : vertices) support.height = std::max(support.height, v.dot(down));
  const Eigen::Vector3d e1 = down.unitOrthogonal();
  const Eigen::Vector3d e2 = down.cross(e1);
  std::vector<Eigen::Vector2d> contacts;
  for (const Eigen::Vector3d& v : vertices) {
    if (v.dot(down) >= support.height - contact_tolerance) contacts.emplace_back(v.dot(e1), v.dot(e2));
  }
  const std::vector<Eigen::Vector2d> polygon = ConvexHull2d(std::move(contacts));
  support.area = polygon.size() < 3 ? 0.0 : PolygonArea(polygon);
  support.margin = InsideMargin(polygon, Eigen::Vector2d(centre.dot(e1), centre.dot(e2)));
  return support;
}

// Turns `down` to -z, the table plane to z = 0 and the centre of mass above the origin.
RestingPose PoseOf(const Support& support, const Eigen::Vector3d& centre) {
  RestingPose pose;
  const Eigen::Matrix3d rotation =
      Eigen::Quaterniond::FromTwoVectors(support.down, -Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d turned = rotation * centre;
  pose.table_from_object.linear() = rotation;
  pose.table_from_object.translation() = Eigen::Vector3d(-turned.x(), -turned.y(), support.height);
  pose.support_area_m2 = support.area;
  pose.margin_m = support.margin;
  return pose;
}

}  // namespace

void RestingPoseOptions::Check() const {
  const auto check = [](double value, const char* field) {
    if (!std::isfinite(value) || value < 0.0) {
      ThrowInputError("resting pose options", field, "a finite value >= 0", std::to_string(value));
    }
  };
  check(contact_tolerance_m, "contact_tolerance_m");
  check(min_margin_m, "min_margin_m");
  check(merge_deg, "merge_deg");
  check(separation_deg, "separation_deg");
}

std::vector<RestingPose> RestingPoses(const TriangleMesh& mesh, const RestingPoseOptions& options) {
  options.Check();
  const std::vector<Eigen::Vector3d> vertices = Vertices(mesh);
  if (vertices.size() < 4) return {};
  const Eigen::Vector3d centre = CentreOfMass(mesh, vertices);
  const double size = (mesh.BoundingBox().max() - mesh.BoundingBox().min()).norm();
  std::vector<ConvexHull3d::Facet> facets = ConvexHull3d(vertices, 1e-7 * size).Facets();
  std::vector<Support> supports;
  for (const Eigen::Vector3d& down : MergedNormals(std::move(facets), options.merge_deg)) {
    supports.push_back(EvaluateSupport(vertices, centre, down, options.contact_tolerance_m));
  }
  if (supports.empty()) return {};
  std::sort(supports.begin(), supports.end(), [](const Support& a, const Support& b) { return a.area > b.area; });
  const double separation_cos = std::cos(options.separation_deg * kPi / 180.0);
  std::vector<RestingPose> poses;
  std::vector<Eigen::Vector3d> kept;
  for (const Support& support : supports) {
    if (support.margin < options.min_margin_m) continue;
    const bool near_kept = std::any_of(kept.begin(), kept.end(),
                                       [&](const Eigen::Vector3d& d) { return d.dot(support.down) > separation_cos; });
    if (near_kept) continue;
    kept.push_back(support.down);
    poses.push_back(PoseOf(support, centre));
  }
  if (poses.empty()) {
    const auto steadiest = std::max_element(supports.begin(), supports.end(),
                                            [](const Support& a, const Support& b) { return a.margin < b.margin; });
    poses.push_back(PoseOf(*steadiest, centre));
  }
  return poses;
}

std::vector<cv::Point2f> Footprint(const TriangleMesh& mesh, const Eigen::Isometry3d& table_from_object) {
  std::vector<Eigen::Vector2d> points;
  points.reserve(mesh.NumVertices());
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3f& p : part.positions) points.push_back((table_from_object * p.cast<double>()).head<2>());
  }
  std::vector<cv::Point2f> footprint;
  for (const Eigen::Vector2d& p : ConvexHull2d(std::move(points))) {
    footprint.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  return footprint;
}

}  // namespace ecv::bench
