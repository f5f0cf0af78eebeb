#include "io/assimp_worker.h"

#include <algorithm>

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/GltfMaterial.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <new>
#include <unordered_map>

#include "io/assimp_precheck.h"
#include "core/files.h"
#include "retile/io.h"
#include "retile/log.h"
#include "scene/validate.h"

namespace fs = std::filesystem;

namespace retile {
namespace {

struct Converter {
  const aiScene* ai;
  fs::path file;
  Scene scene;
  std::vector<std::string> warnings;
  std::vector<NodeId> meshIds;      // per aiMesh, kNoNode if unusable
  std::vector<NodeId> materialIds;  // per aiMaterial
  std::unordered_map<std::string, NodeId> textureIds;
  std::unordered_map<std::string, Mat4> nodeWorld;  // for cameras and lights, by node name
  int nodesVisited = 0;
  bool gltf = false;

  // Printed at once, so that the warnings leading up to a failure still reach the user.
  void warn(std::string w) {
    warnings.push_back(cat(file.filename().string(), ": ", std::move(w)));
    std::fprintf(stderr, "warning: %s\n", warnings.back().c_str());
  }

  static Mat4 toMat4(const aiMatrix4x4& a) {
    Mat4 m;
    const float* src = &a.a1;  // aiMatrix4x4 is row-major a1..a4, b1..b4, ...
    for (int i = 0; i < 16; ++i) m.m[i / 4][i % 4] = src[i];
    return m;
  }

  NodeId texture(const aiMaterial* mat, aiTextureType type, TextureColorSpace cs) {
    if (mat->GetTextureCount(type) == 0) return kNoNode;
    aiString path;
    if (mat->GetTexture(type, 0, &path) != AI_SUCCESS || path.length == 0) return kNoNode;
    std::string ref(path.C_Str());
    std::string key = cat(ref, "|", static_cast<int>(cs));
    if (auto it = textureIds.find(key); it != textureIds.end()) return it->second;
    Texture t;
    t.id = scene.newId();
    t.colorSpace = cs;
    if (const aiTexture* emb = ai->GetEmbeddedTexture(ref.c_str())) {
      if (emb->mHeight != 0 || !emb->pcData || emb->mWidth == 0) {
        warn(cat("embedded texture '", ref, "' is stored uncompressed, which is not supported; using a substitute"));
        return kNoNode;
      }
      t.kind = TextureKind::Embedded;
      t.name = cat("embedded ", ref);
      const auto* bytes = reinterpret_cast<const std::uint8_t*>(emb->pcData);
      t.encoded.assign(bytes, bytes + emb->mWidth);
      t.encodedFormat = emb->achFormatHint;
    } else {
      t.kind = TextureKind::File;
      t.name = fs::path(ref).filename().string();
      t.path = ref;
      if (!resolveScenePath(file.parent_path(), ref)) warn(cat("texture '", ref, "' not found; it will render as a magenta checker"));
    }
    scene.textures.push_back(t);
    textureIds[key] = t.id;
    return t.id;
  }

  // Gulbrandsen's mapping from a normal-incidence reflectance to a complex index, with the edge
  // tint equal to the reflectance: glTF metals give a colour, our conductors want eta and k.
  static void reflectanceToIor(Vec3 r, Vec3* eta, Vec3* k) {
    for (int i = 0; i < 3; ++i) {
      float ri = std::clamp(r[i], 0.0f, 0.99f);
      float g = ri;
      float nMin = (1 - ri) / (1 + ri);
      float sq = std::sqrt(ri);
      float nMax = (1 + sq) / (1 - sq);
      float n = g * nMin + (1 - g) * nMax;
      float k2 = ((n + 1) * (n + 1) * ri - (n - 1) * (n - 1)) / (1 - ri);
      (*eta)[i] = n;
      (*k)[i] = std::sqrt(std::max(k2, 0.0f));
    }
  }

  Material material(const aiMaterial* mat, unsigned index) {
    Material m;
    m.id = scene.newId();
    aiString name;
    m.name = (mat->Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length) ? name.C_Str() : cat("material ", index);

    aiColor4D c;
    float f = 0;
    bool pbr = false;
    Vec3 base{0.8f};
    if (mat->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS) {
      base = {c.r, c.g, c.b};
      pbr = true;
    } else if (mat->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS) {
      base = {c.r, c.g, c.b};
    }
    if (!isFinite(base)) base = Vec3{0.8f};
    m.albedo = base;
    NodeId baseTex = texture(mat, aiTextureType_BASE_COLOR, TextureColorSpace::Auto);
    if (baseTex == kNoNode) baseTex = texture(mat, aiTextureType_DIFFUSE, TextureColorSpace::Auto);
    if (baseTex != kNoNode) {
      m.albedoTexture = baseTex;
      // OBJ/FBX diffuse colours often sit at 0 beside a texture that they do not modulate.
      if (!pbr && maxComponent(base) <= 0.0f) m.albedo = Vec3{1.0f};
    }

    float metallic = 0, roughness = 0.5f;
    bool hasMetallic = mat->Get(AI_MATKEY_METALLIC_FACTOR, metallic) == AI_SUCCESS;
    bool hasRoughness = mat->Get(AI_MATKEY_ROUGHNESS_FACTOR, roughness) == AI_SUCCESS;
    pbr = pbr || hasMetallic || hasRoughness;
    roughness = std::isfinite(roughness) ? std::clamp(roughness, 0.0f, 1.0f) : 0.5f;
    metallic = std::isfinite(metallic) ? std::clamp(metallic, 0.0f, 1.0f) : 0.0f;

    if (pbr) {
      // glTF roughness is perceptual; GGX alpha is its square.
      m.roughness = std::max(roughness * roughness, 0.002f);
      if (metallic >= 0.5f) {
        m.type = MaterialType::RoughConductor;
        m.metal = "custom";
        reflectanceToIor(base, &m.eta, &m.k);
        m.albedo = Vec3{1.0f};
        m.albedoTexture = kNoNode;
        if (baseTex != kNoNode) warn(cat("material '", m.name, "': metal colour textures are not supported; using the base colour factor"));
      } else {
        m.type = MaterialType::RoughPlastic;
        m.ior = 1.5f;
      }
    } else {
      aiColor4D spec;
      float shininess = 0;
      bool hasSpec = mat->Get(AI_MATKEY_COLOR_SPECULAR, spec) == AI_SUCCESS && std::max({spec.r, spec.g, spec.b}) > 0.01f;
      if (hasSpec) {
        m.type = MaterialType::RoughPlastic;
        mat->Get(AI_MATKEY_SHININESS, shininess);
        // Blinn-Phong exponent to an equivalent GGX alpha.
        m.roughness = std::isfinite(shininess) && shininess > 0 ? std::clamp(std::sqrt(2.0f / (shininess + 2.0f)), 0.01f, 1.0f) : 0.3f;
      } else {
        m.type = MaterialType::Lambert;
      }
    }

    if (mat->Get(AI_MATKEY_COLOR_EMISSIVE, c) == AI_SUCCESS) {
      Vec3 e{c.r, c.g, c.b};
      float scale = 1;
      if (mat->Get(AI_MATKEY_EMISSIVE_INTENSITY, f) == AI_SUCCESS && std::isfinite(f)) scale = f;
      e = e * scale;
      if (isFinite(e) && maxComponent(e) > 0) {
        m.emission = max(e, Vec3{0.0f});
        if (!pbr) m.albedo = Vec3{0.0f};  // OBJ lights (Ke) are black emitters
      }
    }

    // Emission is the factor times the texture (glTF's emissiveTexture, OBJ's map_Ke): with a
    // factor of 0 the texture is linked but gives nothing until the factor is raised.
    if (NodeId emissionTex = texture(mat, aiTextureType_EMISSIVE, TextureColorSpace::Auto); emissionTex != kNoNode)
      m.emissionTexture = emissionTex;

    float opacity = 1;
    aiString alphaMode;
    // glTF copies baseColorFactor.a into opacity even for OPAQUE materials, where it means nothing.
    bool opaqueGltf = gltf && !(mat->Get(AI_MATKEY_GLTF_ALPHAMODE, alphaMode) == AI_SUCCESS && std::string(alphaMode.C_Str()) != "OPAQUE");
    if (!opaqueGltf && mat->Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && std::isfinite(opacity) && opacity < 0.999f) {
      int illum = 0;
      mat->Get("$mat.illum", 0, 0, illum);  // OBJ illumination model; 4, 6, 7 and 9 are glass
      float ior = 1.5f;
      if (mat->Get(AI_MATKEY_REFRACTI, ior) != AI_SUCCESS || !std::isfinite(ior) || ior < 1.0f) ior = 1.5f;
      if (illum == 4 || illum == 6 || illum == 7 || illum == 9) {
        m.type = MaterialType::Dielectric;
        m.ior = ior;
        m.albedo = Vec3{1.0f};
      } else {
        m.alpha = std::clamp(opacity, 0.0f, 1.0f);
      }
    }
    float transmission = 0;
    if (mat->Get(AI_MATKEY_TRANSMISSION_FACTOR, transmission) == AI_SUCCESS && transmission > 0.5f) {
      m.type = roughness > 0.05f ? MaterialType::RoughDielectric : MaterialType::Dielectric;
      float ior = 1.5f;
      if (mat->Get(AI_MATKEY_REFRACTI, ior) == AI_SUCCESS && std::isfinite(ior) && ior >= 1.0f) m.ior = ior;
      // KHR_materials_volume: white light turns attenuationColor after attenuationDistance inside,
      // an absorption of -ln(color) / distance. Only with a thickness: a thickness of 0 (the
      // extension's default) is thin-walled, where the volume does not apply.
      float thickness = 0, distance = 0;
      aiColor3D color(1, 1, 1);
      if (mat->Get(AI_MATKEY_VOLUME_THICKNESS_FACTOR, thickness) == AI_SUCCESS && thickness > 0 &&
          mat->Get(AI_MATKEY_VOLUME_ATTENUATION_DISTANCE, distance) == AI_SUCCESS && std::isfinite(distance) && distance > 0 &&
          mat->Get(AI_MATKEY_VOLUME_ATTENUATION_COLOR, color) == AI_SUCCESS) {
        auto absorption = [&](float turned) {
          return std::isfinite(turned) ? -std::log(std::clamp(turned, 1e-6f, 1.0f)) / distance : 0.0f;
        };
        m.interiorAbsorption = Vec3{absorption(color.r), absorption(color.g), absorption(color.b)};
      }
    }
    // glTF's KHR_materials_clearcoat: a layer of index 1.5 over the base, weighed by its factor,
    // which a coat has no weight for: at least half is a coat, as transmission is glass.
    float clearcoat = 0, clearcoatRoughness = 0;
    if (mat->Get(AI_MATKEY_CLEARCOAT_FACTOR, clearcoat) == AI_SUCCESS && clearcoat >= 0.5f && !isTransmissiveType(m.type)) {
      m.coatIor = 1.5f;
      mat->Get(AI_MATKEY_CLEARCOAT_ROUGHNESS_FACTOR, clearcoatRoughness);
      const float alpha = std::isfinite(clearcoatRoughness) ? std::clamp(clearcoatRoughness, 0.0f, 1.0f) : 0.0f;
      m.coatRoughness = alpha * alpha >= 1e-3f ? alpha * alpha : 0.0f;  // perceptual roughness, squared
    }
    NodeId alphaTex = texture(mat, aiTextureType_OPACITY, TextureColorSpace::Raw);
    if (alphaTex != kNoNode) m.alphaTexture = alphaTex;
    return m;
  }

  void visit(const aiNode* node, const Mat4& parent, int depth) {
    if (!node) {
      warn("the file's node tree has an empty entry; skipped");
      return;
    }
    if (depth > 256 || ++nodesVisited > 1'000'000) {
      warn("the node tree is deeper or larger than supported; the rest was skipped");
      return;
    }
    Mat4 world = parent * toMat4(node->mTransformation);
    if (!world.isFinite()) {
      warn(cat("node '", node->mName.C_Str(), "' has a non-finite transform; skipped"));
      return;
    }
    nodeWorld.emplace(node->mName.C_Str(), world);
    if (node->mNumMeshes && !node->mMeshes) warn("a node lists meshes without indices; skipped");
    for (unsigned i = 0; node->mMeshes && i < node->mNumMeshes; ++i) {
      unsigned mi = node->mMeshes[i];
      if (mi >= meshIds.size() || meshIds[mi] == kNoNode) continue;
      const aiMesh* am = ai->mMeshes[mi];
      Object o;
      o.id = scene.newId();
      std::string nodeName = node->mName.C_Str();
      o.name = nodeName.empty() ? cat("object ", scene.objects.size()) : nodeName;
      if (node->mNumMeshes > 1 && am->mName.length) o.name = cat(o.name, " / ", am->mName.C_Str());
      o.mesh = meshIds[mi];
      o.material = am->mMaterialIndex < materialIds.size() ? materialIds[am->mMaterialIndex] : kNoNode;
      o.transform = world;
      scene.objects.push_back(o);
    }
    if (node->mNumChildren && !node->mChildren) return;
    for (unsigned i = 0; i < node->mNumChildren; ++i) visit(node->mChildren[i], world, depth + 1);
  }

  NodeId mesh(const aiMesh* am, unsigned index) {
    if (!am || !am->mVertices || am->mNumVertices == 0 || !am->mFaces || am->mNumFaces == 0) return kNoNode;
    auto g = std::make_shared<MeshGeometry>();
    g->positions.resize(am->mNumVertices);
    for (unsigned v = 0; v < am->mNumVertices; ++v) g->positions[v] = {am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z};
    if (am->mNormals) {
      g->normals.resize(am->mNumVertices);
      for (unsigned v = 0; v < am->mNumVertices; ++v) g->normals[v] = {am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z};
    }
    if (am->mTextureCoords[0]) {
      g->uvs.resize(am->mNumVertices);
      for (unsigned v = 0; v < am->mNumVertices; ++v) g->uvs[v] = {am->mTextureCoords[0][v].x, am->mTextureCoords[0][v].y};
    }
    std::size_t skipped = 0;
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3 || !face.mIndices) {
        ++skipped;
        continue;
      }
      for (int k = 0; k < 3; ++k) g->indices.push_back(face.mIndices[k]);
    }
    if (skipped) warn(cat("mesh ", index, ": skipped ", skipped, " faces that are not triangles"));
    std::size_t dropped = sanitizeGeometry(*g);
    if (dropped)
      warn(
          cat("mesh ", index, " ('", am->mName.C_Str(), "'): dropped ", dropped, " triangles with NaN, infinite or out-of-range vertices"));
    if (g->indices.empty()) return kNoNode;
    Mesh m;
    m.id = scene.newId();
    m.name = am->mName.length ? am->mName.C_Str() : cat("mesh ", index);
    m.geometry = std::move(g);
    scene.meshes.push_back(std::move(m));
    return scene.meshes.back().id;
  }

  void lightsAndCamera() {
    for (unsigned i = 0; ai->mLights && i < ai->mNumLights; ++i) {
      const aiLight* al = ai->mLights[i];
      if (!al) continue;
      auto it = nodeWorld.find(al->mName.C_Str());
      Mat4 world = it != nodeWorld.end() ? it->second : Mat4{};
      Light l;
      l.id = scene.newId();
      l.name = al->mName.length ? al->mName.C_Str() : cat("light ", i);
      Vec3 color{al->mColorDiffuse.r, al->mColorDiffuse.g, al->mColorDiffuse.b};
      float power = maxComponent(color);
      if (!isFinite(color) || power <= 0) continue;
      l.color = color / power;
      l.intensity = power;
      l.position = world.transformPoint({al->mPosition.x, al->mPosition.y, al->mPosition.z});
      l.direction = normalize(world.transformVector({al->mDirection.x, al->mDirection.y, al->mDirection.z}));
      if (length(l.direction) == 0) l.direction = {0, -1, 0};
      switch (al->mType) {
        case aiLightSource_POINT: l.type = LightType::Point; break;
        case aiLightSource_SPOT:
          l.type = LightType::Spot;
          l.spotAngle = std::isfinite(al->mAngleOuterCone) ? std::clamp(al->mAngleOuterCone, 0.01f, kPi / 2) : radians(30);
          l.spotBlend = std::isfinite(al->mAngleInnerCone) ? std::clamp(1 - al->mAngleInnerCone / l.spotAngle, 0.0f, 1.0f) : 0.1f;
          break;
        case aiLightSource_DIRECTIONAL: l.type = LightType::Directional; break;
        default: warn(cat("light '", l.name, "' is of a type we do not render (area/ambient); skipped")); continue;
      }
      if (!isFinite(l.position) || !isFinite(l.direction)) continue;
      scene.lights.push_back(l);
    }

    Bounds3 b = scene.worldBounds();
    Vec3 center = b.empty() ? Vec3{0.0f} : b.center();
    float radius = b.empty() ? 1.0f : std::max(0.5f * length(b.extent()), 1e-3f);
    if (!isFinite(center) || !std::isfinite(radius)) {
      center = Vec3{0.0f};
      radius = 1.0f;
    }
    if (ai->mCameras && ai->mNumCameras > 0 && ai->mCameras[0]) {
      const aiCamera* ac = ai->mCameras[0];
      auto it = nodeWorld.find(ac->mName.C_Str());
      Mat4 world = it != nodeWorld.end() ? it->second : Mat4{};
      Camera cam;
      // Assimp 5.2.5 puts a glTF camera's translation both in mPosition and in its node
      // (assimp issue 5054), so for glTF only the node counts.
      Vec3 local = gltf ? Vec3{0, 0, 0} : Vec3{ac->mPosition.x, ac->mPosition.y, ac->mPosition.z};
      cam.position = world.transformPoint(local);
      Vec3 look = normalize(world.transformVector({ac->mLookAt.x, ac->mLookAt.y, ac->mLookAt.z}));
      cam.target = cam.position + look * radius;
      cam.up = normalize(world.transformVector({ac->mUp.x, ac->mUp.y, ac->mUp.z}));
      float aspect = ac->mAspect > 0 && std::isfinite(ac->mAspect) ? ac->mAspect : scene.aspect();
      float halfH = std::isfinite(ac->mHorizontalFOV) && ac->mHorizontalFOV > 0 ? ac->mHorizontalFOV : kPi / 4;
      // For glTF, 5.2.5 stores yfov * aspect rather than a horizontal angle.
      cam.verticalFov = gltf ? std::clamp(halfH / aspect, 0.01f, 3.0f) : 2 * std::atan(std::tan(std::min(halfH, 1.5f)) / aspect);
      if (isFinite(cam.position) && isFinite(cam.target) && length(look) > 0 && length(cam.up) > 0) {
        scene.camera = cam;
        return;
      }
      warn("the file's camera is unusable; framing the scene instead");
    }
    // No camera: the front view (from +z, y up) with the model's front face filling the frame,
    // through a 70 mm-like lens (19.5 degrees vertical), the framing look-dev shots and the
    // classic Cornell box use. The image takes the front face's aspect ratio.
    Camera cam;
    cam.verticalFov = radians(19.5f);
    Vec3 half = b.empty() ? Vec3{1.0f} : b.extent() * 0.5f;
    float aspect = std::clamp(half.y > 0 ? half.x / half.y : 1.0f, 0.5f, 2.0f);
    scene.settings.height = 512;
    scene.settings.width = static_cast<int>(std::lround(512 * aspect));
    float fit = std::max(half.y, half.x / aspect);
    float dist = std::max(fit, 1e-3f) / std::tan(cam.verticalFov * 0.5f) + half.z;
    cam.target = center;
    cam.position = center + Vec3{0, 0, dist};
    scene.camera = cam;
  }

  void run() {
    scene.baseDirectory = file.parent_path();
    if (ai->mNumMaterials && !ai->mMaterials) throw Error("material list missing");
    for (unsigned i = 0; i < ai->mNumMaterials; ++i) {
      if (!ai->mMaterials[i]) {
        materialIds.push_back(kNoNode);
        continue;
      }
      Material m = material(ai->mMaterials[i], i);
      scene.materials.push_back(m);
      materialIds.push_back(m.id);
    }
    if (ai->mNumMeshes && !ai->mMeshes) throw Error("mesh list missing");
    for (unsigned i = 0; i < ai->mNumMeshes; ++i) meshIds.push_back(mesh(ai->mMeshes[i], i));
    visit(ai->mRootNode, Mat4{}, 0);
    if (scene.objects.empty()) throw Error("the file contains no triangle meshes");
    lightsAndCamera();
    // Most models bring no lighting: a sky lights them until the user adds more. A file with its
    // own lights or emitters (an OBJ Cornell box) is a closed set-up, and a sky would add light.
    bool lit = !scene.lights.empty() ||
               std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) { return maxComponent(m.emission) > 0; });
    scene.environment.type = lit ? EnvironmentType::Constant : EnvironmentType::Sky;
    scene.environment.color = Vec3{0.0f};
    scene.environment.intensity = 1.0f;
  }
};

// Collects the errors Assimp logs. When the import still succeeds they describe what it dropped
// or replaced (a mesh with NaN positions, an unknown material), so the user sees them as warnings.
class CollectingAssimpLog : public Assimp::LogStream {
 public:
  explicit CollectingAssimpLog(std::vector<std::string>* out) : out_(out) {}
  void write(const char* message) override {
    std::string m(message ? message : "");
    while (!m.empty() && (m.back() == '\n' || m.back() == '\r')) m.pop_back();
    if (auto p = m.find(", T0: "); p != std::string::npos) m.erase(0, p + 6);  // "Error, T0: "
    // Messages quote bytes of hostile files: keep them printable and short.
    for (char& c : m)
      if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
    if (m.size() > 200) m = m.substr(0, 200) + "...";
    if (!m.empty() && std::find(out_->begin(), out_->end(), m) == out_->end()) out_->push_back(m);
  }

 private:
  std::vector<std::string>* out_;
};

}  // namespace

Result<std::string> convertWithAssimp(const fs::path& file) {
  using R = Result<std::string>;
  Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);  // no default streams
  std::vector<std::string> assimpErrors;
  struct KillLogger {  // after the importer is gone, before the errors its log stream fills
    ~KillLogger() { Assimp::DefaultLogger::kill(); }
  } killLogger;
  Assimp::DefaultLogger::get()->attachStream(new CollectingAssimpLog(&assimpErrors), Assimp::Logger::Err);
  auto checked = precheckAssimpInput(file);
  if (!checked) return R::failure(checked.error());
  for (const auto& w : checked.value()) std::fprintf(stderr, "warning: %s: %s\n", file.filename().string().c_str(), w.c_str());
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  importer.SetPropertyBool(AI_CONFIG_PP_FD_REMOVE, true);
  // Assimp's area test uses an absolute 1e-6 and deletes every triangle of a model authored in
  // small units (Khronos' MetalRoughSpheres). Zero-area triangles are never hit, so keeping them is harmless.
  importer.SetPropertyBool(AI_CONFIG_PP_FD_CHECKAREA, false);
  // Files without normals get smooth ones, but not across hard edges: Assimp's default of 175
  // degrees rounds a box's corners into its faces (the Cornell box's blocks shade wrongly).
  importer.SetPropertyFloat(AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, 60.0f);
  unsigned flags = aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_JoinIdenticalVertices |
                   aiProcess_GenSmoothNormals | aiProcess_FindInvalidData | aiProcess_FindDegenerates;
  const aiScene* ai = importer.ReadFile(file.string(), flags);
  if (!ai) {
    std::string why = importer.GetErrorString();
    return R::failure(why.empty() ? "Assimp could not read the file" : why);
  }
  if (ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE) return R::failure("the file holds no complete scene (animation or skeleton data only)");
  Converter conv{ai, file, {}, {}, {}, {}, {}, {}, 0, false};
  std::string ext = lowercase(file.extension().string());
  conv.gltf = ext == ".gltf" || ext == ".glb";
  try {
    conv.run();  // refuses a file it cannot use (no triangle meshes, ...) by throwing Error
  } catch (const Error& e) {
    return R::failure(e.what());
  }
  const std::size_t kShown = 6;
  for (std::size_t i = 0; i < assimpErrors.size() && i < kShown; ++i)
    std::fprintf(stderr, "warning: %s: Assimp: %s\n", file.filename().string().c_str(), assimpErrors[i].c_str());
  if (assimpErrors.size() > kShown)
    std::fprintf(stderr, "warning: %s: Assimp reported %zu more problems\n", file.filename().string().c_str(),
                 assimpErrors.size() - kShown);
  // The conversion is written as JSON, which has no infinities: values a hostile file leaves
  // out of range are repaired or refused here, and the parent checks the scene it reads again.
  std::vector<std::string> repairs;
  if (auto valid = validateScene(conv.scene, repairs); !valid) return R::failure(valid.error());
  for (const std::string& r : repairs) std::fprintf(stderr, "warning: %s: %s\n", file.filename().string().c_str(), r.c_str());
  return nativeSceneToString(conv.scene);
}

int assimpWorkerMain(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "error: usage: retile-import-worker FILE\n");
    return 2;
  }
  try {
    auto out = convertWithAssimp(argv[1]);
    if (!out) {
      std::fprintf(stderr, "error: %s\n", out.error().c_str());
      return 2;
    }
    std::fwrite(out->data(), 1, out->size(), stdout);
    std::fflush(stdout);
    return 0;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: ran out of memory (the importer's memory limit was reached)\n");
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}

}  // namespace retile
