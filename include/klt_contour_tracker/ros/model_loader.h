#pragma once
/// \file model_loader.h
/// The tracked object's model for the nodelet: a link of a URDF (~model_description +
/// ~object_link, its visuals merged in the link frame) or a single mesh resource
/// (~mesh_resource + ~mesh_scale). Resources are package://, file:// or plain paths (resolved on
/// disk so that assimp finds .mtl files and textures next to the mesh) or any other URL
/// resource_retriever can fetch (downloaded into a temporary directory; relative textures are
/// then not found). The mesh is in the object frame (the link frame), metres.

#include <Eigen/Core>
#include <string>

#include "klt_contour_tracker/core/mesh.h"

namespace klt_contour_tracker {

struct NodeletConfig;

/// The model the configuration names: load_model_from_urdf(config.model_description,
/// config.object_link) when ~model_description is set, else
/// load_model_from_resource(config.mesh_resource, config.mesh_scale). Throws std::runtime_error
/// whose message starts with the parameter ("~model_description: ...", "~mesh_resource: ...")
/// and says why (URDF parse error, unknown link with the available links, link without
/// visuals, missing package or file, mesh assimp cannot read, mesh without faces).
kct::Mesh load_model(const NodeletConfig& config);

/// One mesh in metres: the resource's vertices multiplied by `scale` (model units -> metres).
/// Throws std::runtime_error naming the URL and the reason; also for a mesh with no faces and
/// a non-positive or non-finite scale.
kct::Mesh load_model_from_resource(const std::string& url, double scale);

/// Same with a per-axis scale (URDF <mesh scale="x y z">); a mirroring scale (an odd number of
/// negative factors) reverses the winding so that faces stay counter-clockwise from outside.
kct::Mesh load_model_from_resource(const std::string& url, const Eigen::Vector3d& scale);

/// The visuals of link `link_name` of the URDF `urdf_xml`, each placed at its <origin> in the
/// link frame and merged (kct::append_mesh), metres. Geometry: <mesh filename scale>, and
/// <box>, <cylinder> (axis z) and <sphere> tessellated by the functions below. Throws
/// std::runtime_error: unparsable URDF, unknown link (the message lists the links), a link
/// without <visual>, or a visual that cannot be loaded (named by its index and file).
kct::Mesh load_model_from_urdf(const std::string& urdf_xml, const std::string& link_name);

/// Local file of a resource: file:// and plain paths as they are, package://pkg/rest as
/// <path of pkg>/rest. Empty for any other scheme (to be fetched by resource_retriever).
/// Throws std::runtime_error when the package is not found or the file does not exist.
std::string resolve_resource_path(const std::string& url);

/// Box of edge lengths `size` (metres) centred on the origin, 12 faces.
kct::Mesh make_box_mesh(const Eigen::Vector3d& size);
/// Closed cylinder along z, centred on the origin (URDF convention), `segments` sides.
kct::Mesh make_cylinder_mesh(double radius, double length, int segments = 48);
/// Sphere centred on the origin: an icosphere with `subdivisions` levels (3 -> 1280 faces).
kct::Mesh make_sphere_mesh(double radius, int subdivisions = 3);

}  // namespace klt_contour_tracker
