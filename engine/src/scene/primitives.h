// Procedural meshes for the default scene and for the analytic primitives of scene files.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "retile/scene.h"

namespace retile {

// Unit square in the XZ plane, x and z in [-0.5, 0.5], facing +y, uv over [0,1]^2.
std::shared_ptr<const MeshGeometry> makeQuad();
// Cube [-0.5, 0.5]^3 with flat faces facing outwards.
std::shared_ptr<const MeshGeometry> makeCube();
// Sphere of radius 1 about the origin, smooth normals.
std::shared_ptr<const MeshGeometry> makeSphere(int rings = 48, int segments = 96);
// Surface of revolution about +y through the (radius, height) points of `profile`, in order.
std::shared_ptr<const MeshGeometry> makeLathe(const std::vector<Vec2>& profile, int segments);

// Cylinder about +y of radius 0.5 and height 1 centred on the origin; `capped` closes its ends
// with flat discs (their own vertices, so the rims shade sharp).
std::shared_ptr<const MeshGeometry> makeCylinder(bool capped, int segments = 64);

// Adding nodes with fresh ids, for scenes built in code (the built-in scene, benchmarks, the
// stability suite). Each returns the new node's id.
NodeId addMesh(Scene& s, std::string name, std::shared_ptr<const MeshGeometry> g);
NodeId addMaterial(Scene& s, Material m);
NodeId addObject(Scene& s, std::string name, NodeId mesh, NodeId material, const Mat4& xf);
// A mesh, its own material and an object using both: `name` names all three.
NodeId addMeshObject(Scene& s, const std::string& name, std::shared_ptr<const MeshGeometry> g, Material m, const Mat4& xf);

}  // namespace retile
