// Reading and writing scenes. Every function here may be called from any thread (the editor
// calls them from a worker); they share no state. Failures are Result values whose message
// names the file and the problem; nothing here throws for bad input.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "retile/error.h"
#include "retile/scene.h"

namespace retile {

struct ImportOptions {
  // Limits for the child process that runs Assimp: a hang or a memory blow-up becomes an error.
  std::chrono::milliseconds assimpTimeout{60000};
  std::uint64_t assimpMemoryLimit = std::uint64_t(6) << 30;
  // Upper bounds that keep hostile files from exhausting memory in our own parsers.
  std::uint64_t maxFileBytes = std::uint64_t(2) << 30;
  std::uint64_t maxTriangles = 50'000'000;
};

struct ImportedScene {
  Scene scene;
  std::string format;                 // "tungsten", "assimp:gltf", "native", ...
  std::vector<std::string> warnings;  // missing textures, dropped NaN vertices, substitutes
};

// Chooses the importer by content and extension: native (.retile), Tungsten/Bitterli JSON
// (.json), everything else through Assimp in a child process.
Result<ImportedScene> importScene(const std::filesystem::path& file, const ImportOptions& options = {});

// Whether a renderer's warning about a scene's file ("FILE: problem", Renderer::setScene) names a
// file that one of `importWarnings`, the same scene's import warnings, already named: the import
// said what stands in for it, so the renderer's is the same news again. Any thread.
bool importReported(const std::string& renderWarning, const std::vector<std::string>& importWarnings);

Result<ImportedScene> importTungsten(const std::filesystem::path& file, const ImportOptions& options = {});
Result<ImportedScene> importAssimp(const std::filesystem::path& file, const ImportOptions& options = {});
Result<ImportedScene> loadNativeScene(const std::filesystem::path& file, const ImportOptions& options = {});

// Reads an OBJ file's triangles (positions, normals, uvs) as one mesh, ignoring materials.
// Used for Tungsten meshes; NaN/Inf vertices are dropped with a warning.
Result<MeshGeometry> readObjGeometry(const std::filesystem::path& file, std::vector<std::string>* warnings,
                                     const ImportOptions& options = {});

// The native format: versioned JSON; mesh data and embedded images inline (base64), so one file
// holds the whole scene. Written atomically: a failed save leaves the old file intact.
constexpr int kNativeFormatVersion = 1;
Result<bool> saveNativeScene(const Scene& scene, const std::filesystem::path& file);
std::string nativeSceneToString(const Scene& scene);
Result<ImportedScene> nativeSceneFromString(const std::string& text, const std::filesystem::path& nameForErrors,
                                            const std::filesystem::path& baseDirectory);

// Replaces every NaN/Inf position triangle and every out-of-range index; returns how many
// triangles were dropped. Shared by all importers so the renderer only sees finite geometry.
// `perTriangle` (one entry per input triangle, e.g. a material index) keeps the kept ones' entries.
std::size_t sanitizeGeometry(MeshGeometry& g, std::vector<std::int32_t>* perTriangle = nullptr);

}  // namespace retile
