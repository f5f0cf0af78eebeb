#include "core/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>

#include "retile/log.h"

namespace fs = std::filesystem;

namespace retile {

Result<std::string> readFile(const fs::path& path, std::uint64_t maxBytes) {
  std::error_code ec;
  auto status = fs::status(path, ec);
  if (ec || !fs::exists(status)) return Result<std::string>::failure(cat(path.string(), ": file not found"));
  if (fs::is_directory(status)) return Result<std::string>::failure(cat(path.string(), ": is a directory, not a file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) return Result<std::string>::failure(cat(path.string(), ": cannot open: ", std::strerror(errno)));
  in.seekg(0, std::ios::end);
  auto size = static_cast<std::uint64_t>(in.tellg());
  if (size > maxBytes)
    return Result<std::string>::failure(cat(path.string(), ": file is ", size, " bytes, more than the limit of ", maxBytes));
  in.seekg(0);
  std::string data(size, '\0');
  in.read(data.data(), static_cast<std::streamsize>(size));
  if (!in) return Result<std::string>::failure(cat(path.string(), ": read error"));
  return data;
}

namespace {

// A save's temporary is ".STEM.tmpXXXXXX.EXT" beside the file: hidden, and found again by the
// prefix when a killed save left it behind.
std::string temporaryPrefix(const fs::path& path) { return cat(".", path.stem().string(), ".tmp"); }

}  // namespace

fs::path temporarySibling(const fs::path& path) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  fs::path p = path;
  p.replace_filename(cat(temporaryPrefix(path), std::hex, rng() & 0xffffff, path.extension().string()));
  return p;
}

Result<bool> writeFileAtomic(const fs::path& path, std::string_view bytes) {
  fs::path tmp = temporarySibling(path);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return Result<bool>::failure(cat(path.string(), ": cannot create a temporary file beside it: ", std::strerror(errno)));
  std::size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      std::string why = std::strerror(errno);
      ::close(fd);
      ::unlink(tmp.c_str());
      return Result<bool>::failure(cat(path.string(), ": write failed (", why, "); the existing file is unchanged"));
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    return Result<bool>::failure(cat(path.string(), ": flushing failed (", why, "); the existing file is unchanged"));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    return Result<bool>::failure(cat(path.string(), ": rename failed (", why, "); the existing file is unchanged"));
  }
  removeStaleTemporaries(path);
  return true;
}

// A save killed between creating its temporary and the rename (kill -9, power loss) leaves the
// hidden temporary behind. The next save of the same file removes those older than ten minutes:
// no save takes that long, so none of them can belong to a save still running.
void removeStaleTemporaries(const fs::path& path) {
  std::error_code ec;
  const std::string prefix = temporaryPrefix(path);
  const std::string suffix = path.extension().string();
  const auto cutoff = fs::file_time_type::clock::now() - std::chrono::minutes(10);
  fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() < prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    std::error_code fileEc;
    if (it->is_regular_file(fileEc) && it->last_write_time(fileEc) < cutoff && !fileEc) fs::remove(it->path(), fileEc);
  }
}

std::string lowercase(std::string_view s) {
  std::string r(s);
  for (char& c : r)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return r;
}

std::string extensionLower(const fs::path& path) {
  std::string e = lowercase(path.extension().string());
  return e.empty() ? e : e.substr(1);
}

std::optional<fs::path> resolveScenePath(const fs::path& base, std::string_view reference) {
  std::string ref(reference);
  for (char& c : ref)
    if (c == '\\') c = '/';
  // "./x" and ".\x" (Windows exporters) mean the same as "x".
  while (ref.rfind("./", 0) == 0) ref.erase(0, 2);
  if (ref.empty()) return std::nullopt;
  fs::path p(ref);
  fs::path full = p.is_absolute() ? p : base / p;
  std::error_code ec;
  if (fs::is_regular_file(full, ec)) return full;

  // Walk the components, matching each case-insensitively against the directory's entries.
  fs::path current = p.is_absolute() ? fs::path("/") : base;
  for (const auto& part : p.relative_path()) {
    std::string name = part.string();
    if (name.empty() || name == ".") continue;
    if (name == "..") {
      current = current / "..";
      continue;
    }
    fs::path exact = current / part;
    if (fs::exists(exact, ec)) {
      current = exact;
      continue;
    }
    std::string want = lowercase(name);
    bool found = false;
    for (fs::directory_iterator it(current, ec), end; !ec && it != end; it.increment(ec)) {
      if (lowercase(it->path().filename().string()) == want) {
        current = it->path();
        found = true;
        break;
      }
    }
    if (!found) return std::nullopt;
  }
  if (fs::is_regular_file(current, ec)) return current;
  return std::nullopt;
}

namespace {
const char kB64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
}

std::string base64Encode(const std::uint8_t* data, std::size_t size) {
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < size; i += 3) {
    std::uint32_t v = (std::uint32_t(data[i]) << 16) | (std::uint32_t(data[i + 1]) << 8) | data[i + 2];
    out += kB64[(v >> 18) & 63];
    out += kB64[(v >> 12) & 63];
    out += kB64[(v >> 6) & 63];
    out += kB64[v & 63];
  }
  if (i < size) {
    std::uint32_t v = std::uint32_t(data[i]) << 16;
    if (i + 1 < size) v |= std::uint32_t(data[i + 1]) << 8;
    out += kB64[(v >> 18) & 63];
    out += kB64[(v >> 12) & 63];
    out += (i + 1 < size) ? kB64[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

Result<std::vector<std::uint8_t>> base64Decode(std::string_view text) {
  int table[256];
  for (int& t : table) t = -1;
  for (int i = 0; i < 64; ++i) table[static_cast<unsigned char>(kB64[i])] = i;
  std::vector<std::uint8_t> out;
  out.reserve(text.size() / 4 * 3);
  std::uint32_t acc = 0;
  int bits = 0;
  std::size_t padding = 0;
  for (char c : text) {
    if (c == '=') {
      ++padding;
      continue;
    }
    if (padding) return Result<std::vector<std::uint8_t>>::failure("base64: data after padding");
    int v = table[static_cast<unsigned char>(c)];
    if (v < 0) return Result<std::vector<std::uint8_t>>::failure("base64: invalid character");
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>((acc >> bits) & 0xff));
    }
  }
  if (padding > 2) return Result<std::vector<std::uint8_t>>::failure("base64: too much padding");
  return out;
}

std::uint64_t fnv1a64(std::string_view data, std::uint64_t seed) {
  std::uint64_t h = seed;
  for (unsigned char c : data) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

}  // namespace retile
