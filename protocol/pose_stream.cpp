#include "protocol/pose_stream.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/geometry/rotation.h"

namespace hapticd::proto {
namespace {

constexpr std::string_view kHeader = "t,px,py,pz,qx,qy,qz,qw,buttons";
constexpr std::array<std::string_view, 9> kColumns = {"t",  "px", "py", "pz",     "qx",
                                                      "qy", "qz", "qw", "buttons"};
constexpr std::size_t kMaxFields = kColumns.size();

std::string_view trimmed(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos)
    return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// a field as an error shows it: quoted, cut after 40 characters
std::string shown(std::string_view field) {
  constexpr std::size_t kMax = 40;
  if (field.size() > kMax)
    return "'" + std::string(field.substr(0, kMax)) + "...'";
  return "'" + std::string(field) + "'";
}

// the lenient dialect's "column C (name): "
std::string columnOf(std::size_t column) {
  return "column " + std::to_string(column) + " (" + std::string(kColumns[column - 1]) + "): ";
}

std::string fmt17(double v) {
  std::ostringstream o;
  o.precision(17);
  o << v;
  return o.str();
}

// One stream's parse: the dialect's grammar around one set of checks, and its error wording.
class Parser {
 public:
  Parser(std::string_view source, double quat_tolerance, PoseStreamDialect dialect)
      : source_(source),
        tolerance_(quat_tolerance),
        strict_(dialect == PoseStreamDialect::kStrict) {}

  Result<std::vector<PoseStreamRow>> run(std::string_view text);

 private:
  // "SOURCE: line L[, column C (name)]: strict_text" or "SOURCE:L: lenient_text"
  Error fail(std::size_t column,
             const std::string& strict_text,
             const std::string& lenient_text) const;
  // lenient: true for a header line to skip, an error for a bad one, false for a row
  Result<bool> header(std::string_view line) const;
  Result<PoseStreamRow> row(std::string_view line);
  Result<double> number(std::size_t column, std::string_view field) const;
  Result<std::uint32_t> buttons(std::string_view field) const;
  Result<bool> checkRow(PoseStreamRow& r,
                        const std::array<double, 8>& v,
                        const std::array<std::string_view, kMaxFields>& f);

  std::string_view source_;
  double tolerance_;
  bool strict_;
  std::size_t line_no_ = 0;
  std::vector<PoseStreamRow> rows_;
};

Error Parser::fail(std::size_t column,
                   const std::string& strict_text,
                   const std::string& lenient_text) const {
  std::string s(source_);
  if (!strict_)
    return Error{s + ":" + std::to_string(line_no_) + ": " + lenient_text};
  s += ": line " + std::to_string(line_no_);
  if (column > 0)
    s += ", column " + std::to_string(column) + " (" + std::string(kColumns[column - 1]) + ")";
  return Error{s + ": " + strict_text};
}

Result<std::vector<PoseStreamRow>> Parser::run(std::string_view text) {
  bool seen_header = false;
  std::size_t blank_line = 0;  // strict: the first blank line seen (allowed only at the end)
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no_;
    if (strict_) {
      if (!line.empty() && line.back() == '\r')
        line.remove_suffix(1);
      if (line.empty()) {
        if (blank_line == 0)
          blank_line = line_no_;
        continue;
      }
      if (blank_line != 0) {
        line_no_ = blank_line;
        return fail(0, "empty line inside the stream", "");
      }
      if (!seen_header) {
        if (line != kHeader)
          return fail(
              0, "the header must be exactly '" + std::string(kHeader) + "', got " + shown(line),
              "");
        seen_header = true;
        continue;
      }
    } else {
      line = trimmed(line);
      if (line.empty() || line[0] == '#')
        continue;
      const auto is_header = header(line);
      if (!is_header)
        return is_header.error();
      if (is_header.value())
        continue;
    }
    auto r = row(line);
    if (!r)
      return r.error();
    rows_.push_back(r.value());
  }
  if (strict_ && !seen_header)
    return Error{std::string(source_) + ": empty file (no header)"};
  if (rows_.empty())
    return Error{std::string(source_) + (strict_ ? ": no rows after the header" : ": no rows")};
  return std::move(rows_);
}

Result<bool> Parser::header(std::string_view line) const {
  if (trimmed(line.substr(0, line.find(','))) != "t")
    return false;
  std::size_t n = 0;
  bool same = true;
  for (std::size_t at = 0; at <= line.size(); ++n) {
    const std::size_t comma = std::min(line.find(',', at), line.size());
    same = same && n < kMaxFields && trimmed(line.substr(at, comma - at)) == kColumns[n];
    at = comma + 1;
  }
  if (same && (n == kMaxFields || n == kMaxFields - 1) && rows_.empty())
    return true;
  return fail(0, "",
              rows_.empty() ? "header must be t,px,py,pz,qx,qy,qz,qw,buttons"
                            : "a header after the first row");
}

Result<PoseStreamRow> Parser::row(std::string_view line) {
  // the fields; one more than a row may have tells "too many"
  std::array<std::string_view, kMaxFields> f;
  std::size_t n = 0;
  bool more = false;
  for (std::size_t at = 0; at <= line.size();) {
    const std::size_t comma = std::min(line.find(',', at), line.size());
    if (n == kMaxFields) {
      more = true;
      break;
    }
    f[n++] = strict_ ? line.substr(at, comma - at) : trimmed(line.substr(at, comma - at));
    at = comma + 1;
  }
  if (!strict_ && (more || n < kMaxFields - 1)) {
    std::size_t count = 0;
    for (char c : line)
      count += c == ',' ? 1u : 0u;
    return fail(0, "",
                "expected 9 columns t,px,py,pz,qx,qy,qz,qw,buttons (buttons may be left out), "
                "got " +
                    std::to_string(count + 1));
  }
  PoseStreamRow r;
  std::array<double, 8> v{};
  for (std::size_t i = 0; i < std::min<std::size_t>(n, 8); ++i) {
    auto x = number(i + 1, f[i]);
    if (!x)
      return x.error();
    v[i] = x.value();
  }
  if (n == kMaxFields) {
    auto b = buttons(f[8]);
    if (!b)
      return b.error();
    r.buttons = b.value();
  }
  if (more)
    return fail(0, "more than " + std::to_string(kMaxFields) + " fields", "");
  if (strict_ && n != kMaxFields)
    return fail(0, std::to_string(n) + " fields, expected " + std::to_string(kMaxFields), "");
  auto checked = checkRow(r, v, f);
  if (!checked)
    return checked.error();
  return r;
}

Result<double> Parser::number(std::size_t column, std::string_view field) const {
  if (field.empty())
    return fail(column, "empty field", columnOf(column) + "'' is not a number");
  const char* first = field.data();
  const char* last = field.data() + field.size();
  // from_chars takes no leading '+'; allow it as a CSV writer may emit it
  const char* begin = (*first == '+' && field.size() > 1) ? first + 1 : first;
  double x = 0.0;
  const auto [ptr, ec] = std::from_chars(begin, last, x);
  const std::string q = shown(field);
  const std::string c = columnOf(column);
  if (ec == std::errc::result_out_of_range)
    return fail(column, "number out of range: " + q, c + q + " is not finite");
  if (ec != std::errc() || ptr != last)
    return fail(column, "not a number: " + q, c + q + " is not a number");
  if (!std::isfinite(x))
    return fail(column, "not a finite number: " + q, c + q + " is not finite");
  return x;
}

Result<std::uint32_t> Parser::buttons(std::string_view field) const {
  if (field.empty()) {
    if (strict_)
      return fail(9, "empty field", "");
    return std::uint32_t{0};  // lenient: buttons left out
  }
  const char* first = field.data();
  const char* last = field.data() + field.size();
  if (!strict_ && *first == '+' && field.size() > 1)
    ++first;
  std::uint32_t b = 0;
  const auto [ptr, ec] = std::from_chars(first, last, b);
  if (ec == std::errc() && ptr == last)
    return b;
  const std::string q = shown(field);
  const std::string lenient = columnOf(9) + q + " is not an unsigned 32-bit integer";
  if (ec == std::errc::result_out_of_range)
    return fail(9, "button mask out of range (32 bits): " + q, lenient);
  return fail(9, "not a non-negative integer bit mask: " + q, lenient);
}

Result<bool> Parser::checkRow(PoseStreamRow& r,
                              const std::array<double, 8>& v,
                              const std::array<std::string_view, kMaxFields>& f) {
  r.t_s = v[0];
  if (strict_ && r.t_s < 0.0)
    return fail(1, "time before 0: " + std::to_string(r.t_s), "");
  if (!rows_.empty() && !(r.t_s > rows_.back().t_s)) {
    if (strict_)
      return fail(
          1, "time not after the previous row's (" + std::to_string(rows_.back().t_s) + " s)", "");
    return fail(0, "",
                "t " + std::string(f[0]) + " is not after the previous row's t " +
                    fmt17(rows_.back().t_s) + " (t must increase)");
  }
  const double norm = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
  if (!(std::abs(norm - 1.0) <= tolerance_)) {
    std::ostringstream msg;
    msg << "quaternion (columns 5-8) of length " << norm << ", not within " << tolerance_
        << " of 1";
    return fail(5, msg.str(),
                "quaternion (" + std::string(f[4]) + ", " + std::string(f[5]) + ", " +
                    std::string(f[6]) + ", " + std::string(f[7]) + ") has norm " + fmt17(norm) +
                    ", not 1 (within " + fmt17(tolerance_) + ")");
  }
  r.X_WD.translation = geom::Vec3(v[1], v[2], v[3]);
  r.X_WD.rotation = geom::Quat(v[7] / norm, v[4] / norm, v[5] / norm, v[6] / norm);
  return true;
}

}  // namespace

Result<std::vector<PoseStreamRow>> parsePoseStream(std::string_view text,
                                                   std::string_view source,
                                                   double quat_tolerance,
                                                   PoseStreamDialect dialect) {
  return Parser(source, quat_tolerance, dialect).run(text);
}

Result<std::string> readPoseStreamFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return Error{"cannot open the file (missing or unreadable)"};
  if (!std::filesystem::is_regular_file(path, ec))
    return Error{"not a regular file"};
  std::ifstream in{path, std::ios::binary};
  if (!in)
    return Error{"cannot open the file (missing or unreadable)"};
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0)
    return Error{"cannot read the file (not a regular file?)"};
  if (static_cast<std::uintmax_t>(size) > kMaxPoseStreamBytes)
    return Error{"file larger than 1 GiB"};
  in.seekg(0, std::ios::beg);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), size))
    return Error{"cannot read the file"};
  return text;
}

PoseStreamRow samplePoseStream(std::span<const PoseStreamRow> rows,
                               double t_s,
                               std::size_t& cursor) noexcept {
  const std::size_t n = rows.size();
  if (n == 1 || !(t_s > rows.front().t_s)) {  // also NaN
    cursor = 0;
    return {t_s, rows.front().X_WD, rows.front().buttons};
  }
  if (t_s >= rows.back().t_s) {
    cursor = n - 1;
    return {t_s, rows.back().X_WD, rows.back().buttons};
  }
  // the cursor moves forward a few rows per tick; a jump back or far ahead searches
  if (cursor >= n - 1 || rows[cursor].t_s > t_s)
    cursor = 0;
  std::size_t steps = 0;
  while (rows[cursor + 1].t_s <= t_s) {
    if (++steps > 8) {
      const auto it =
          std::upper_bound(rows.begin() + static_cast<std::ptrdiff_t>(cursor), rows.end(), t_s,
                           [](double t, const PoseStreamRow& r) { return t < r.t_s; });
      cursor = static_cast<std::size_t>(it - rows.begin()) - 1;
      break;
    }
    ++cursor;
  }
  const PoseStreamRow& a = rows[cursor];
  const PoseStreamRow& b = rows[cursor + 1];
  const double s = (t_s - a.t_s) / (b.t_s - a.t_s);
  PoseStreamRow out{t_s, {}, a.buttons};
  out.X_WD.translation = a.X_WD.translation + s * (b.X_WD.translation - a.X_WD.translation);
  out.X_WD.rotation = geom::slerp(a.X_WD.rotation, b.X_WD.rotation, s);
  return out;
}

}  // namespace hapticd::proto
