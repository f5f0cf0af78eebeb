// The built-in look-dev scene. Everything is generated here, so `retile render default` and the
// editor's first start need no files. Its pieces exercise what look-dev needs: a glossy sphere,
// a small cup beside a reflective panel (the object the Fig. 6 script moves), a textured box, an
// area light and a sky.
#include "retile/scene.h"
#include "scene/primitives.h"

namespace retile {

Scene makeDefaultScene() {
  Scene s;
  s.settings.width = 640;
  s.settings.height = 360;
  s.settings.maxBounces = 8;
  s.settings.samplesPerPixel = 64;

  NodeId quad = addMesh(s, "Quad", makeQuad());
  NodeId cube = addMesh(s, "Cube", makeCube());
  NodeId sphere = addMesh(s, "Sphere", makeSphere());
  NodeId cup = addMesh(s, "Cup",
                       makeLathe({{0.0f, 0.0f},
                                  {0.085f, 0.0f},
                                  {0.1f, 0.01f},
                                  {0.11f, 0.06f},
                                  {0.12f, 0.2f},
                                  {0.12f, 0.21f},
                                  {0.108f, 0.21f},
                                  {0.098f, 0.06f},
                                  {0.085f, 0.018f},
                                  {0.0f, 0.018f}},
                                 64));

  Texture checker;
  checker.id = s.newId();
  checker.name = "Checker";
  checker.kind = TextureKind::Checker;
  checker.checkerOn = {0.85f, 0.82f, 0.75f};
  checker.checkerOff = {0.12f, 0.2f, 0.35f};
  checker.checkerResU = 6;
  checker.checkerResV = 6;
  s.textures.push_back(checker);

  Material ground;
  ground.name = "Ground";
  ground.type = MaterialType::RoughPlastic;
  ground.albedo = {0.55f, 0.55f, 0.55f};
  ground.roughness = 0.35f;
  NodeId groundMat = addMaterial(s, ground);

  Material glossy;
  glossy.name = "Red Lacquer";
  glossy.type = MaterialType::RoughPlastic;
  glossy.albedo = {0.7f, 0.08f, 0.06f};
  glossy.roughness = 0.06f;
  NodeId glossyMat = addMaterial(s, glossy);

  Material ceramic;
  ceramic.name = "Ceramic";
  ceramic.type = MaterialType::Plastic;
  ceramic.albedo = {0.85f, 0.85f, 0.8f};
  NodeId ceramicMat = addMaterial(s, ceramic);

  Material steel;
  steel.name = "Brushed Steel";
  steel.type = MaterialType::RoughConductor;
  steel.metal = "Al";
  steel.albedo = Vec3{1.0f};
  steel.roughness = 0.03f;
  NodeId steelMat = addMaterial(s, steel);

  Material checkered;
  checkered.name = "Checkered";
  checkered.type = MaterialType::Lambert;
  checkered.albedoTexture = checker.id;
  NodeId checkerMat = addMaterial(s, checkered);

  Material light;
  light.name = "Light";
  light.type = MaterialType::Lambert;
  light.albedo = Vec3{0.0f};
  light.emission = Vec3{12.0f, 11.0f, 9.5f};
  NodeId lightMat = addMaterial(s, light);

  addObject(s, "Ground", quad, groundMat, Mat4::scale({12, 1, 12}));
  addObject(s, "Glossy Sphere", sphere, glossyMat, Mat4::translate({-0.85f, 0.45f, 0.1f}) * Mat4::scale(Vec3{0.45f}));
  addObject(s, "Cup", cup, ceramicMat, Mat4::translate({0.35f, 0.0f, 0.35f}));
  addObject(s, "Steel Panel", cube, steelMat,
            Mat4::translate({0.3f, 0.45f, -0.25f}) * Mat4::rotateY(radians(-8.0f)) * Mat4::scale({1.1f, 0.9f, 0.04f}));
  addObject(s, "Checkered Box", cube, checkerMat,
            Mat4::translate({1.35f, 0.3f, 0.25f}) * Mat4::rotateY(radians(30.0f)) * Mat4::scale(Vec3{0.6f}));
  // Facing down: the quad's front is +y, so flip it.
  addObject(s, "Area Light", quad, lightMat, Mat4::translate({-0.6f, 3.0f, 1.2f}) * Mat4::rotateX(kPi) * Mat4::scale({1.2f, 1.0f, 1.2f}));

  s.environment.type = EnvironmentType::Sky;
  s.environment.intensity = 0.8f;

  s.camera.position = {0.6f, 1.35f, 3.9f};
  s.camera.target = {0.15f, 0.35f, 0.0f};
  s.camera.verticalFov = radians(34.0f);
  return s;
}

}  // namespace retile
