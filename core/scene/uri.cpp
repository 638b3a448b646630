#include "core/scene/uri.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "core/scene/json_checker.h"

namespace hapticd::scene::detail {
namespace {

/// The value of a base64 digit, -1 for any other byte.
int base64Digit(char c) {
  if (c >= 'A' && c <= 'Z')
    return c - 'A';
  if (c >= 'a' && c <= 'z')
    return c - 'a' + 26;
  if (c >= '0' && c <= '9')
    return c - '0' + 52;
  if (c == '+' || c == '-')
    return 62;
  if (c == '/' || c == '_')
    return 63;
  return -1;
}

std::string percentDecoded(const std::string& uri) {
  std::string decoded;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      decoded.push_back(static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      decoded.push_back(uri[i]);
    }
  }
  return decoded;
}

/// Why a percent-decoded relative path is refused before the file system is asked, or "".
std::string refusedPath(const std::string& uri, const std::string& decoded) {
  if (decoded.empty() || decoded.find('\0') != std::string::npos)
    return "external URI " + inQuotes(uri) + " is empty or holds a NUL byte";
  if (decoded.front() == '/' || decoded.front() == '\\') {
    return "external URI " + inQuotes(uri) +
           " is an absolute path (only paths inside the allowed folder are read)";
  }
  const std::size_t colon = decoded.find(':');
  if (colon != std::string::npos && decoded.find('/') > colon)
    return "external URI " + inQuotes(uri) + " has a scheme (only relative file paths are read)";
  std::size_t start = 0;
  while (start <= decoded.size()) {
    const std::size_t end = decoded.find_first_of("/\\", start);
    const std::string part =
        decoded.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (part == "..")
      return "external URI " + inQuotes(uri) + " traverses out of the allowed folder ('..')";
    if (end == std::string::npos)
      break;
    start = end + 1;
  }
  return "";
}

}  // namespace

bool isDataUri(const std::string& uri) {
  return uri.rfind("data:", 0) == 0;
}

Result<std::vector<std::uint8_t>> decodeDataUri(const std::string& uri) {
  const std::size_t comma = uri.find(',');
  const std::string header = uri.substr(0, comma);
  if (comma == std::string::npos || header.size() < 7 ||
      header.compare(header.size() - 7, 7, ";base64") != 0) {
    return Error{"the data URI is not base64 ('data:<media type>;base64,<data>')"};
  }
  std::vector<std::uint8_t> out;
  out.reserve((uri.size() - comma) / 4 * 3);
  std::uint32_t acc = 0;
  int bits = 0;
  std::size_t i = comma + 1;
  for (; i < uri.size() && uri[i] != '='; ++i) {
    const int d = base64Digit(uri[i]);
    if (d < 0)
      return Error{"the data URI holds a byte that is not base64 at " + std::to_string(i)};
    acc = (acc << 6) | static_cast<std::uint32_t>(d);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>((acc >> bits) & 0xffu));
    }
  }
  if (std::any_of(uri.begin() + static_cast<std::ptrdiff_t>(i), uri.end(),
                  [](char c) { return c != '='; })) {
    return Error{"the data URI has data after its '=' padding"};
  }
  return out;
}

std::optional<std::string> resolveUri(const std::string& uri,
                                      const LoadOptions& options,
                                      std::string* why) {
  namespace fs = std::filesystem;
  if (!options.allowed_uri_dir) {
    *why = "external URI " + inQuotes(uri) +
           " refused: no folder is allowed for external files (LoadOptions::allowed_uri_dir, "
           "config [scene] allowed_uri_dir)";
    return std::nullopt;
  }
  // percent-decoding, as a file URI is read
  const std::string decoded = percentDecoded(uri);
  *why = refusedPath(uri, decoded);
  if (!why->empty())
    return std::nullopt;
  std::error_code ec;
  const fs::path dir = fs::canonical(*options.allowed_uri_dir, ec);
  if (ec) {
    *why = "the allowed folder " + inQuotes(options.allowed_uri_dir->string()) + " does not exist";
    return std::nullopt;
  }
  const fs::path file = fs::canonical(dir / decoded, ec);
  if (ec) {
    *why = "external URI " + inQuotes(uri) + ": no such file in the allowed folder";
    return std::nullopt;
  }
  // the canonical path (symbolic links resolved) must still be inside the folder
  const auto [d, f] = std::mismatch(dir.begin(), dir.end(), file.begin(), file.end());
  if (d != dir.end()) {
    *why = "external URI " + inQuotes(uri) +
           " resolves outside the allowed folder (a symbolic link out of it?)";
    return std::nullopt;
  }
  if (!fs::is_regular_file(file, ec)) {
    *why = "external URI " + inQuotes(uri) + " is not a regular file";
    return std::nullopt;
  }
  return file.string();
}

Result<std::vector<std::uint8_t>> readFileLimited(const std::string& path,
                                                  std::uint64_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::is_regular_file(status))
    return Error{"cannot read " + path + ": " + (ec ? ec.message() : "not a regular file")};
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec)
    return Error{"cannot read " + path + ": " + ec.message()};
  if (size > max_bytes) {
    return Error{std::to_string(size) + " bytes exceeds max_file_bytes (" +
                 std::to_string(max_bytes) + ")"};
  }
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
  if (!in)
    return Error{"cannot read " + path};
  return bytes;
}

}  // namespace hapticd::scene::detail
