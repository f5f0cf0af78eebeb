// The Tungsten importer (io/tungsten_*.cpp): one TungstenImporter per file read. Tungsten /
// Bitterli scene.json is the format the paper's scenes come in; conventions (transform order,
// Euler angles, shape extents, camera field of view, bounce counting) follow Tungsten so scenes
// look as their authors rendered them (docs/TUNGSTEN.md). Its parts: the scene and its
// settings (tungsten_import.cpp), bsdfs, textures and media (tungsten_bsdfs.cpp), shapes, meshes
// and primitives (tungsten_shapes.cpp). Internal to io/; one thread at a time.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <utility>
#include <vector>
#include "core/files.h"
#include "core/json.h"
#include "io/curve_reader.h"
#include "retile/io.h"
#include "retile/log.h"
#include "scene/curves.h"
#include "scene/primitives.h"

namespace retile::tungsten {

namespace fs = std::filesystem;

using json::Value;

// The scalar Tungsten reads from a colour where it wants one number (TexelConversion::
// REQUEST_AVERAGE: roughness, blend ratios, alpha, bump): the mean of its channels.
inline float channelMean(Vec3 c) { return (c.x + c.y + c.z) / 3.0f; }

struct TextureRef {
  bool isTexture = false;
  Vec3 constant{1.0f};
  NodeId texture = kNoNode;
};

class TungstenImporter {
 public:
  TungstenImporter(fs::path file, const ImportOptions& options) : file_(std::move(file)), options_(options) {
    base_ = file_.parent_path();
    out_.format = "tungsten";
    out_.scene.baseDirectory = base_;
  }

  Result<ImportedScene> run();

 private:
  // The thin lens focuses as far as the origin of the primitive focus_pivot names (Tungsten's
  // ThinlensCamera::prepareForRender), else where focus_distance says.
  void focusOn(const Value& primitives);

  // The transform of the first primitive called `name` (the identity when it has none), or
  // nothing when no primitive is.
  std::optional<Mat4> transformOfPrimitive(const Value& primitives, const std::string& name);

  // A blend's part under the blend's albedo. Where the part is itself a chain of blends, the
  // materials after it are copied under the albedo too (they may be a named bsdf's, which keeps
  // its own); the copies replace what the part's own blend had made for it alone.
  void underAlbedo(Material& p, const TextureRef& albedo, int depth = 0);
  // Materials in the chain of blends that starts at m (m itself counts).
  int chainLength(const Material& m) const;
  // Ends the chain at m after `keep` materials; the last one kept is copied without its blend.
  void cutChain(Material& m, int keep);

  // A named bsdf every user of which took a copy of it (emitters, bump maps) would sit in the
  // material list unused, beside its copies: it goes. Bsdfs the file defines but no primitive
  // names stay, for the artist to assign.
  void dropReplacedBsdfs();

  // Textures read for what is not rendered (a thin sheet's albedo) or for bsdfs
  // that were replaced; otherwise they would be decoded and packed for nothing.
  void dropUnusedTextures();

  // Meshes no object uses (a file only ever used mirrored, whose copy replaced it; one whose
  // primitive was skipped after it loaded), which would be packed and saved for nothing.
  void dropUnusedMeshes();

  bool ok() const { return error_.empty(); }
  Result<ImportedScene> fail(const std::string& what);
  void problem(const std::string& where, const std::string& what);
  void warn(const std::string& what) { out_.warnings.push_back(cat(file_.filename().string(), ": ", what)); }
  std::set<std::string> undefinedWarned_;  // undefined bsdf names already reported

  bool number(const Value& obj, const char* key, float* out, const std::string& where);
  bool vec3(const Value& obj, const char* key, Vec3* out, const std::string& where);
  std::string string(const Value& obj, const char* key, const std::string& fallback = {});

  NodeId fileTexture(const std::string& ref, TextureColorSpace cs, bool interpolate = true, bool clampToEdge = false);

  // A Tungsten texture value: number, [r,g,b], "file", or {type: bitmap|constant|checker}.
  TextureRef texture(const Value& v, const std::string& where, bool data);

  // `emitter`: the primitive carries emission, so an undefined name there stands for Tungsten's
  // null bsdf (published Bitterli-derived files name "null" or "NULL" for their lights without
  // defining it).
  // A bsdf and, in the Tungsten of its newer files, its bump map (Bsdf::fromJson; older files put
  // it on the primitive, which the primitive's copy of the bsdf then takes instead). Read as data,
  // the channels averaged (REQUEST_AVERAGE: Tungsten's gamma table is for colours only), the
  // slope times the bitmap's scale.
  Material bsdf(const Value& v, const std::string& where, int depth = 0, bool emitter = false);

  // The bsdf as its type reads it, without the bump map every type may carry (bsdf adds that).
  Material bsdfOwn(const Value& v, const std::string& where, int depth, bool emitter);
  // A bsdf named by a string: the named one, or a stand-in for an undefined name (warned of once).
  Material namedBsdf(const Value& v, const std::string& where, bool emitter, Material m);
  // Tungsten's transparency: its base bsdf, cut out by alpha.
  Material transparencyBsdf(const Value& v, const std::string& where, int depth, Material m);
  // Tungsten's coats: a dielectric layer over a substrate bsdf (Material::coatIor).
  Material coatBsdf(const Value& v, const std::string& type, const std::string& where, int depth, Material m);
  // Tungsten's blend of two bsdfs (Material::blendWith).
  Material mixedBsdf(const Value& v, const std::string& where, int depth, Material m);
  // The bsdfs that map onto one material type, with the parameters they share (albedo, roughness,
  // distribution).
  Material typedBsdf(const Value& v, const std::string& type, const std::string& where, Material m);

  // Tungsten's hair (HairBcsdf): its melanin gives the pigment's absorption per unit of the
  // fibre's radius (d'Eon et al. 2011's eumelanin and pheomelanin, mixed by the ratio), unless
  // sigma_a is given.
  void hairFibre(const Value& v, const std::string& where, Material& m);

  // Tungsten's rotYXZ: R = Ry(-ry) Rx(rx) Rz(rz), angles in degrees.
  static Mat4 rotation(Vec3 deg);

  // flatY: the shape lies in y = 0 (quad, disk), so a zero y scale means nothing and is
  // replaced by 1 to keep the matrix invertible.
  Mat4 transform(const Value* v, const std::string& where, Vec3* scaleOut = nullptr, bool flatY = false);

  void camera(const Value& c);

  // Tessellated, a sphere or a disk has a little less area than Tungsten's analytic shape (0.09 %
  // for the sphere's 48 x 96, 0.16 % for the disk's 64-gon), and as an emitter gives that much less
  // light, which is most of the 0.2 % a scene lit by them may differ by. Scaled out to the true area.
  static std::shared_ptr<const MeshGeometry> withArea(std::shared_ptr<const MeshGeometry> g, float area);

  // Tungsten's sphere has its poles on z and u = atan2(y, x) / 2 pi + 1/2, v = acos(z) / pi
  // (Sphere::intersectionInfo); ours has them on y. The same mesh turned by (x, y, z) -> (-x, z, y),
  // a rotation, carries uvs that are Tungsten's, so that a textured sphere looks as in Tungsten.
  static std::shared_ptr<const MeshGeometry> tungstenSphere();

  // Tungsten's quad has v = 1/2 - z (Quad::intersect: v = 1 - l1); ours z + 1/2.
  static std::shared_ptr<const MeshGeometry> tungstenQuad();

  // Tungsten's cube maps a face across its other two axes in turn, (y, z) on the x faces, (z, x)
  // on the y faces, (x, y) on the z faces, each from 0 to 1 and unmirrored on either side
  // (Cube::intersectionInfo). Ours spans each face by its own corners.
  static std::shared_ptr<const MeshGeometry> tungstenCube();

  // Tungsten's cylinder has u = atan2(z, x) / 2 pi + 1/2 and v = y + 1/2 on its wall and
  // (x + 1/2, z + 1/2) on its caps (Cylinder::intersectionInfo). Ours, turned half a turn about y
  // (a rotation), has its seam where Tungsten's u wraps and u = 1 - Tungsten's along the wall.
  static std::shared_ptr<const MeshGeometry> tungstenCylinder(bool capped);

  // A disk of radius 1 facing +y whose u runs from 0 to 1 as -x turns towards -z, v from its
  // centre out. Placed by tungstenDiskFrame, that is Tungsten's parametrisation.
  static std::shared_ptr<const MeshGeometry> tungstenDisk(int segments);

  // Tungsten's disk is round whatever its scale: its radius is the larger of the x and z scales,
  // its normal the transformed y axis, and u the angle about it in a frame taken from the normal
  // alone (Disk::prepareForRender, TangentFrame), so the same disk turned about its normal keeps
  // its uvs where they were in the world. The frame's columns are that frame's bitangent, the
  // normal and its tangent, each times the radius.
  static Mat4 tungstenDiskFrame(const Mat4& xf, Vec3 scale);

  std::shared_ptr<const MeshGeometry> shape(const std::string& kind);

  NodeId meshNode(const std::string& key, const std::string& name, std::shared_ptr<const MeshGeometry> g);

  // A copy of `mesh` with every triangle wound the other way. A mesh's normals stay as they are:
  // Tungsten carries them by the normal matrix, as we do. A quad's turn with its winding: its
  // shading normal is its winding's (Quad::intersectionInfo).
  NodeId mirroredMesh(NodeId mesh, bool turnNormals);

  static void smoothNormals(MeshGeometry& g);

  // Tungsten's recompute_normals (TriangleMesh::calcSmoothVertexNormals), rebuilt from what it
  // does: vertices at one position are smoothed together, area-weighted, but not across a crease
  // of more than 27 degrees (cos 0.15 pi). A corner whose face turns further from the first face
  // that used its vertex gets a vertex of its own, which keeps that face's flat normal; a vertex
  // takes the faces around its position within 27 degrees of its own first face. Smoothing by
  // shared index alone rounded a box's edges and left seams where a file splits vertices.
  static void creasedNormals(MeshGeometry& g);

  // The tubes of a "curves" primitive's strands (scene/curves.h), as a mesh: its file (.hair or
  // .fiber) with Tungsten's curve_thickness, curve_taper and subsample applied. (Tungsten widens
  // strands by the transform's mean scale, as a uniform scale does here; under a scale that is
  // not uniform the tubes are flattened where Tungsten's stay round.) kNoNode when there is
  // nothing to draw.
  NodeId curves(const Value& p, const std::string& where);

  // A mesh file's triangles that take the bsdf of one material index.
  struct MeshPart {
    std::int32_t material = 0;
    NodeId mesh = kNoNode;
  };

  // The mesh of a "mesh" primitive: with `split` (the primitive names several bsdfs), one part
  // per material index its triangles carry (a .wo3 file's; an OBJ file's are all 0), each a mesh
  // of its own; else one part, of the first triangle's index. Empty when the file is unusable.
  std::vector<MeshPart> loadMesh(const Value& p, const std::string& where, bool split);

  // Tungsten's binary mesh: uint64 vertex count, {pos, normal, uv} per vertex, uint64 triangle
  // count, {3 x uint32, int32 material} per triangle. `materials` gets the kept triangles' indices.
  Result<MeshGeometry> readWo3(const fs::path& path, std::vector<std::int32_t>* materials);

  static float worldArea(const MeshGeometry& g, const Mat4& m);

  // The sky's frame is its transform's rotation (InfiniteSphere: _rotTransform, scale and position
  // dropped): R = Ry(-ry) Rx(rx) Rz(rz) times the basis of any axes given. Its turn about y is
  // the environment's rotation, the rest (tilts, an "up") its orientation.
  void environmentFromEmission(const Value& p, const std::string& where);

  void environmentEntry(const Value& v, const std::string& where);

  // Tungsten's skydome (the Hosek-Wilkie sky model), drawn as a gradient sky, with a warning.
  void skydome(const Value& p, const std::string& where);
  // A cap of the sky: a sun whose disc is the cap (Light::angularRadius).
  void sphereCap(const Value& p, const std::string& where, const Value* tv);
  // A point light: Tungsten's emission is its intensity (W/sr), its power spreads over 4 pi.
  void pointLight(const Value& p, const std::string& where, const Value* tv);
  // The meshes of a shape primitive (a mesh with several material indices gives one per index),
  // its transform `xf` made Tungsten's for the shape (a round sphere and cylinder, a disk's frame),
  // and a disk's emission cone; none, with a warning, for a type not rendered.
  std::vector<MeshPart> shapeParts(const Value& p, const std::string& type, const std::string& where, Vec3 scale, bool split, Mat4& xf,
                                   float& emissionCone);
  // What a primitive emits (Tungsten's emission, or its power spread over its area): the emission
  // belongs to the primitive in Tungsten and to the material here.
  struct Emission {
    Vec3 radiance{0.0f};
    NodeId texture = kNoNode;
    bool emissive = false;
  };
  Emission emissionOf(const Value& p, const std::string& where, const std::vector<MeshPart>& parts, const Mat4& xf);
  // A medium inside glass or a boundary belongs to the primitive in Tungsten and to the material
  // here (its int_medium fills `mat`); the one outside (ext_medium) is where the path comes from,
  // which it remembers, so it needs nothing if something holds it inside. Returns the medium filled.
  std::string fillMedium(const Value& p, const std::string& where, Material& mat);
  void primitive(const Value& p, const std::string& where);

  fs::path file_;
  fs::path base_;
  ImportOptions options_;
  ImportedScene out_;
  std::string error_;
  std::map<std::string, Material> named_;
  std::string focusPivot_;             // the thin lens camera's focus_pivot
  const Value* primitives_ = nullptr;  // the file's primitives, while they are imported
  std::map<std::string, NodeId> textures_;
  std::set<std::string> missingWarned_;
  bool quietMissingTexture_ = false;
  std::map<std::string, NodeId> meshIds_;
  std::map<NodeId, NodeId> mirroredOf_;                     // a mesh -> its copy wound the other way
  std::map<std::string, std::vector<MeshPart>> meshParts_;  // a mesh file's parts, by loadMesh's key
  std::map<std::string, std::shared_ptr<const MeshGeometry>> shapes_;
  int emitters_ = 0;
  int curvesMeshes_ = 0;
  std::set<NodeId> copied_;  // named bsdfs some primitive took a copy of (dropReplacedBsdfs)
  // (bsdf, bump texture, strength, medium) -> its copy
  std::map<std::tuple<std::string, NodeId, float, std::string>, NodeId> bumped_;
  // A homogeneous medium, as the glass or boundary it fills holds it (Material::interiorAbsorption and on).
  struct Filling {
    Vec3 absorption{0.0f}, scattering{0.0f};
    float anisotropy = 0.0f;
  };
  // Tungsten's homogeneous medium: sigma_a and sigma_s times density, and its phase function
  // (isotropic by default, as in Tungsten's Medium). Read leniently: nothing for a medium that is
  // not understood, with the reason in `why`; the caller names it in a warning and leaves it out.
  // Tungsten's newer media name their transmittance, and write {"type": "exponential"}, the
  // homogeneous medium's own, into every file they save; no key means the same.
  static bool exponentialTransmittance(const Value* t);
  std::optional<Filling> mediumFilling(const Value& medium, const std::string& name, std::string* why);
  std::map<std::string, Filling> media_;                      // homogeneous media by name
  std::set<std::string> mediaNamed_;                          // every medium's name, rendered or not
  std::set<std::string> inside_;                              // the media some glass or boundary holds
  std::vector<std::pair<std::string, std::string>> holders_;  // where a medium is held, and the ext_medium named there
  std::string cameraMedium_;                                  // the camera's
  std::vector<std::pair<std::string, std::string>> outside_;  // where an ext_medium is named, and the name
};

}  // namespace retile::tungsten
