#include "daemon/device/replay_device.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "daemon/device/rotation_util.h"

namespace hapticd::device {

namespace {

constexpr std::string_view kHeader = "t,px,py,pz,qx,qy,qz,qw,buttons";
constexpr std::array<std::string_view, 9> kColumns = {"t",  "px", "py", "pz",     "qx",
                                                      "qy", "qz", "qw", "buttons"};
// a larger file is refused before it is read (about 15 million rows)
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 30;

std::string where(std::string_view source, std::size_t line, std::size_t column) {
  std::string s(source);
  s += ": line " + std::to_string(line);
  if (column > 0)
    s += ", column " + std::to_string(column) + " (" + std::string(kColumns[column - 1]) + ")";
  return s + ": ";
}

std::string shown(std::string_view field) {
  constexpr std::size_t kMax = 40;
  if (field.size() > kMax)
    return "'" + std::string(field.substr(0, kMax)) + "...'";
  return "'" + std::string(field) + "'";
}

}  // namespace

Result<std::vector<PoseStreamRow>> parsePoseStream(std::string_view text,
                                                   std::string_view source,
                                                   double quat_tolerance) {
  std::vector<PoseStreamRow> rows;
  std::size_t line_no = 0;
  std::size_t pos = 0;
  bool seen_header = false;
  std::size_t blank_line = 0;  // the first blank line seen (allowed only at the end)
  while (pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);
    if (line.empty()) {
      if (blank_line == 0)
        blank_line = line_no;
      continue;
    }
    if (blank_line != 0)
      return Error{where(source, blank_line, 0) + "empty line inside the stream"};
    if (!seen_header) {
      if (line != kHeader)
        return Error{where(source, line_no, 0) + "the header must be exactly '" +
                     std::string(kHeader) + "', got " + shown(line)};
      seen_header = true;
      continue;
    }
    PoseStreamRow row;
    std::array<double, 8> v{};
    std::size_t column = 0;
    std::size_t field_start = 0;
    while (true) {
      const std::size_t comma = line.find(',', field_start);
      const std::string_view field =
          line.substr(field_start, comma == std::string_view::npos ? std::string_view::npos
                                                                   : comma - field_start);
      ++column;
      if (column > kColumns.size())
        return Error{where(source, line_no, 0) + "more than " + std::to_string(kColumns.size()) +
                     " fields"};
      const char* first = field.data();
      const char* last = field.data() + field.size();
      if (field.empty())
        return Error{where(source, line_no, column) + "empty field"};
      if (column < kColumns.size()) {
        double x = 0.0;
        // from_chars takes no leading '+'; allow it as a CSV writer may emit it
        const char* begin = (*first == '+' && field.size() > 1) ? first + 1 : first;
        const auto [ptr, ec] = std::from_chars(begin, last, x);
        if (ec == std::errc::result_out_of_range)
          return Error{where(source, line_no, column) + "number out of range: " + shown(field)};
        if (ec != std::errc() || ptr != last)
          return Error{where(source, line_no, column) + "not a number: " + shown(field)};
        if (!std::isfinite(x))
          return Error{where(source, line_no, column) + "not a finite number: " + shown(field)};
        v[column - 1] = x;
      } else {
        std::uint32_t b = 0;
        const auto [ptr, ec] = std::from_chars(first, last, b);
        if (ec == std::errc::result_out_of_range)
          return Error{where(source, line_no, column) +
                       "button mask out of range (32 bits): " + shown(field)};
        if (ec != std::errc() || ptr != last)
          return Error{where(source, line_no, column) +
                       "not a non-negative integer bit mask: " + shown(field)};
        row.buttons = b;
      }
      if (comma == std::string_view::npos)
        break;
      field_start = comma + 1;
    }
    if (column != kColumns.size())
      return Error{where(source, line_no, 0) + std::to_string(column) + " fields, expected " +
                   std::to_string(kColumns.size())};
    row.t_s = v[0];
    if (row.t_s < 0.0)
      return Error{where(source, line_no, 1) + "time before 0: " + std::to_string(row.t_s)};
    if (!rows.empty() && !(row.t_s > rows.back().t_s))
      return Error{where(source, line_no, 1) + "time not after the previous row's (" +
                   std::to_string(rows.back().t_s) + " s)"};
    const double norm = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
    if (!std::isfinite(norm) || std::abs(norm - 1.0) > quat_tolerance) {
      std::ostringstream msg;
      msg << where(source, line_no, 5) << "quaternion (columns 5-8) of length " << norm
          << ", not within " << quat_tolerance << " of 1";
      return Error{msg.str()};
    }
    row.X_WD.translation = Vec3(v[1], v[2], v[3]);
    row.X_WD.rotation = geom::Quat(v[7] / norm, v[4] / norm, v[5] / norm, v[6] / norm);
    rows.push_back(row);
  }
  if (!seen_header)
    return Error{std::string(source) + ": empty file (no header)"};
  if (rows.empty())
    return Error{std::string(source) + ": no rows after the header"};
  return rows;
}

ReplayDevice::ReplayDevice(std::string name,
                           std::vector<PoseStreamRow> rows,
                           const DeviceOptions& options)
    : rows_(std::move(rows)) {
  info_.name = std::move(name);
  info_.capabilities = kCapPosition | kCapOrientation | kCapButtons | kCapEndOfStream;
  info_.limits = options.limits;
}

Pose ReplayDevice::poseAt(double t_s, std::uint32_t* buttons) noexcept {
  const std::size_t n = rows_.size();
  if (n == 1 || !(t_s > rows_.front().t_s)) {  // also NaN
    cursor_ = 0;
    if (buttons)
      *buttons = rows_.front().buttons;
    return rows_.front().X_WD;
  }
  if (t_s >= rows_.back().t_s) {
    cursor_ = n - 1;
    if (buttons)
      *buttons = rows_.back().buttons;
    return rows_.back().X_WD;
  }
  // the cursor moves forward a few rows per tick; a jump back or far ahead searches
  if (cursor_ >= n - 1 || rows_[cursor_].t_s > t_s)
    cursor_ = 0;
  std::size_t steps = 0;
  while (rows_[cursor_ + 1].t_s <= t_s) {
    if (++steps > 8) {
      const auto it =
          std::upper_bound(rows_.begin() + static_cast<std::ptrdiff_t>(cursor_), rows_.end(), t_s,
                           [](double t, const PoseStreamRow& r) { return t < r.t_s; });
      cursor_ = static_cast<std::size_t>(it - rows_.begin()) - 1;
      break;
    }
    ++cursor_;
  }
  const PoseStreamRow& a = rows_[cursor_];
  const PoseStreamRow& b = rows_[cursor_ + 1];
  const double s = (t_s - a.t_s) / (b.t_s - a.t_s);
  if (buttons)
    *buttons = a.buttons;
  Pose X;
  X.translation = a.X_WD.translation + s * (b.X_WD.translation - a.X_WD.translation);
  X.rotation = detail::slerp(a.X_WD.rotation, b.X_WD.rotation, s);
  return X;
}

DeviceStatus ReplayDevice::read(double t_s, DeviceSample& out) noexcept {
  if (t_s > rows_.back().t_s)
    return DeviceStatus::kEndOfStream;
  if (std::isnan(t_s))
    t_s = has_previous_ ? previous_t_s_ : rows_.front().t_s;  // bad clock
  std::uint32_t buttons = 0;
  const Pose X = poseAt(t_s, &buttons);
  out.X_WD = X;
  out.buttons = buttons;
  if (has_previous_ && t_s > previous_t_s_) {
    const double dt = t_s - previous_t_s_;
    out.linear_velocity = (X.translation - previous_pose_.translation) / dt;
    out.angular_velocity =
        detail::rotationVector(X.rotation * glm::conjugate(previous_pose_.rotation)) / dt;
  } else {
    out.linear_velocity = Vec3(0.0);
    out.angular_velocity = Vec3(0.0);
  }
  has_previous_ = true;
  previous_t_s_ = t_s;
  previous_pose_ = X;
  return DeviceStatus::kOk;
}

Result<std::unique_ptr<Device>> makeReplayDevice(std::string_view file,
                                                 const DeviceOptions& options) {
  const std::string name = "replay:" + std::string(file);
  if (!(options.replay_quat_tolerance >= 0.0 && options.replay_quat_tolerance < 1.0))
    return Error{"device '" + name + "': replay_quat_tolerance must be in [0, 1)"};
  std::error_code ec;
  if (!std::filesystem::exists(std::string(file), ec))
    return Error{"device '" + name + "': cannot open the file (missing or unreadable)"};
  if (!std::filesystem::is_regular_file(std::string(file), ec))
    return Error{"device '" + name + "': not a regular file"};
  std::ifstream in{std::string(file), std::ios::binary};
  if (!in)
    return Error{"device '" + name + "': cannot open the file (missing or unreadable)"};
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0)
    return Error{"device '" + name + "': cannot read the file (not a regular file?)"};
  if (static_cast<std::uintmax_t>(size) > kMaxFileBytes)
    return Error{"device '" + name + "': file larger than 1 GiB"};
  in.seekg(0, std::ios::beg);
  std::string text(static_cast<std::size_t>(size), '\0');
  if (!in.read(text.data(), size))
    return Error{"device '" + name + "': cannot read the file"};
  auto rows = parsePoseStream(text, name, options.replay_quat_tolerance);
  if (!rows)
    return rows.error();
  return std::unique_ptr<Device>(
      std::make_unique<ReplayDevice>(name, std::move(rows).value(), options));
}

}  // namespace hapticd::device
