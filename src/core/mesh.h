#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace ecv {

/// How a mesh part gets its colour when rendered.
enum class MeshColoring { kTexture, kVertexColor, kMaterialColor };

/// Name for messages: "texture", "vertex colour", "material colour".
const char* ToString(MeshColoring coloring);

/// Surface appearance shared by mesh parts.
struct MeshMaterial {
  std::string name;
  Eigen::Vector3f diffuse_color{0.8F, 0.8F, 0.8F};  ///< RGB in [0, 1], used where there is no texture
  cv::Mat texture;                                  ///< CV_8UC3 RGB as stored (row 0 = v = 1); empty if none
  std::string texture_path;                         ///< resolved file, "" if none, "*N" if embedded
};

/// Triangles of one material. Vertex attributes are parallel arrays; optional ones are empty.
struct MeshPart {
  std::vector<Eigen::Vector3f> positions;  ///< object frame, metres
  std::vector<Eigen::Vector3f> normals;    ///< unit, object frame; empty if none
  std::vector<Eigen::Vector2f> texcoords;  ///< (u, v), OBJ convention: texture row = (1 - v) * height
  std::vector<Eigen::Vector3f> colors;     ///< per-vertex RGB in [0, 1]; empty if none
  std::vector<Eigen::Vector3i> triangles;  ///< indices into the vertex arrays
  int material = -1;                       ///< index into TriangleMesh::materials, -1 for none
};

/// `texture` with its longer side at most `max_side` pixels: larger ones are downscaled (cv::INTER_AREA, aspect
/// kept), others returned as they are (sharing pixels). The one rule of the renderer's texture cap and of stored
/// meshes (io/mesh_blob.h), so that both give the same pixels; 0 keeps every size.
cv::Mat CapTextureSize(const cv::Mat& texture, int max_side);

/// A box along a point set's principal axes.
struct PrincipalBox {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();      ///< the middle of the extent along the axes, metres
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();    ///< unit columns, least spread first
  Eigen::Vector3d half_sizes = Eigen::Vector3d::Zero();  ///< along each axis, metres
};

/// A triangle mesh in the object frame (metres), as loaded by io/mesh_io.h.
struct TriangleMesh {
  std::string name;  ///< file stem unless given
  std::vector<MeshPart> parts;
  std::vector<MeshMaterial> materials;

  size_t NumVertices() const;
  size_t NumTriangles() const;

  /// Colouring of one part: texture if its material has an image and the part has texcoords, else
  /// vertex colours if present, else the material colour.
  MeshColoring Coloring(const MeshPart& part) const;

  /// Axis-aligned box of all vertices, metres; empty box for an empty mesh.
  Eigen::AlignedBox3d BoundingBox() const;

  /// Largest distance between two vertices, metres (exact; as BOP's models_info "diameter").
  double Diameter() const;

  /// The box along the principal axes of the vertices (eigenvectors of their scatter) that holds them all; the
  /// identity axes and a zero box for an empty mesh.
  PrincipalBox PrincipalAxesBox() const;

  /// True when the triangles, over all parts, close into surfaces whose faces all turn their counter-clockwise
  /// side outwards: every edge (vertices compared by position, so texture seams do not open it) is run through
  /// as often in one direction as in the other (once each but where surfaces pinch), and the enclosed volume is
  /// positive (triangles with two corners at one position cover nothing and are left out). Only then may a renderer
  /// skip the faces turned away from the camera (RenderOptions::cull_back_faces) without changing the image.
  bool IsClosedOutward() const;

  /// Maps every position and normal by `new_from_old` (x_new = R x_old + t).
  void Transform(const Eigen::Isometry3d& new_from_old);

  /// Multiplies every position by `factor` (a unit change).
  void Scale(double factor);
};

}  // namespace ecv
