// File helpers shared by the importers and writers. Any thread.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "retile/error.h"

namespace retile {

// Reads a whole file; fails with a message naming the file when it is missing, unreadable, a
// directory, or larger than maxBytes.
Result<std::string> readFile(const std::filesystem::path& path, std::uint64_t maxBytes = std::uint64_t(1) << 32);

// Writes `bytes` to a temporary file beside `path`, flushes it to disk and renames it over
// `path`, so a crash or a full disk never leaves a half-written file in its place.
Result<bool> writeFileAtomic(const std::filesystem::path& path, std::string_view bytes);
// Removes the hidden temporaries of `path`'s saves that were killed before their rename, those
// older than ten minutes (writeFileAtomic calls it after each successful save).
void removeStaleTemporaries(const std::filesystem::path& path);

// Temporary name beside `path` that keeps its extension (image writers choose the format by it).
std::filesystem::path temporarySibling(const std::filesystem::path& path);

// Finds a file named by a scene: accepts either path separator and matches every component
// case-insensitively when the exact name does not exist (files made on Windows name textures
// TEST.PNG while the disk holds test.png). Returns nullopt when nothing matches.
std::optional<std::filesystem::path> resolveScenePath(const std::filesystem::path& base, std::string_view reference);

std::string lowercase(std::string_view s);
std::string extensionLower(const std::filesystem::path& path);  // without the dot

std::string base64Encode(const std::uint8_t* data, std::size_t size);
Result<std::vector<std::uint8_t>> base64Decode(std::string_view text);

// FNV-1a, for cache keys (not for security).
std::uint64_t fnv1a64(std::string_view data, std::uint64_t seed = 0xcbf29ce484222325ull);

}  // namespace retile
