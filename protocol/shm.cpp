#include "protocol/shm.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>

#include "protocol/auth.h"

namespace hapticd::proto {
namespace {

constexpr std::size_t kStateOffset = sizeof(ShmHeader);
constexpr std::size_t alignUp(std::size_t v, std::size_t a) {
  return (v + a - 1) / a * a;
}
constexpr std::size_t kRingOffset = alignUp(kStateOffset + sizeof(ShmStateBlock), 64);
constexpr std::size_t kSegmentBytes = alignUp(kRingOffset + sizeof(ShmRing), 4096);
static_assert(kShmRingSlots >= 2 && (kShmRingSlots & (kShmRingSlots - 1)) == 0);

ShmHeader* header(void* base) {
  return static_cast<ShmHeader*>(base);
}
ShmStateBlock* stateBlock(void* base) {
  return reinterpret_cast<ShmStateBlock*>(static_cast<char*>(base) + kStateOffset);
}
ShmRing* ring(void* base) {
  return reinterpret_cast<ShmRing*>(static_cast<char*>(base) + kRingOffset);
}

std::string hex32(std::uint32_t v) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", v);
  return text;
}

bool finiteAll(const double* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i]))
      return false;
  return true;
}

}  // namespace

void toState(const ShmState& in, State& out) {
  auto pose = [](const double* x) {
    WirePose p;
    for (std::size_t i = 0; i < 3; ++i)
      p.p[i] = x[i];
    for (std::size_t i = 0; i < 4; ++i)
      p.q[i] = x[3 + i];
    return p;
  };
  auto u32 = [](std::uint64_t v) {
    return static_cast<std::uint32_t>(std::min<std::uint64_t>(v, UINT32_MAX));
  };
  out.tick = in.tick;
  out.sim_time_ns = in.sim_time_ns;
  out.X_WD = pose(in.X_WD);
  out.X_WP = pose(in.X_WP);
  for (std::size_t i = 0; i < 3; ++i) {
    out.force_n[i] = in.force_n[i];
    out.torque_nm[i] = in.torque_nm[i];
  }
  out.force_scale = in.force_scale;
  out.last_command_sequence = in.last_command_sequence;
  out.tick_misses = in.tick_misses;
  out.tick_p50_ns = u32(in.tick_p50_ns);
  out.tick_p99_ns = u32(in.tick_p99_ns);
  out.tick_max_ns = u32(in.tick_max_ns);
  out.fault_bits = u32(in.fault_bits);
  out.state_flags = u32(in.state_flags);
  out.contact_count = u32(in.contact_count);
  out.contacts.clear();
  out.bodies.clear();
  const std::size_t n = std::min<std::uint64_t>(in.body_count, kShmBodies);
  for (std::size_t b = 0; b < n; ++b)
    out.bodies.push_back({u32(in.bodies[b].index), pose(in.bodies[b].X_WB)});
  out.pairs_tested = u32(in.pairs_tested);
  out.pairs_skipped = u32(in.pairs_skipped);
  out.max_penetration_m = std::isfinite(in.max_penetration_m) && in.max_penetration_m > 0.0
                              ? in.max_penetration_m
                              : 0.0;
  out.tick_ns = u32(in.tick_ns);
}

// ---- server --------------------------------------------------------------------------------

ShmExisting inspectShm(const std::string& name) {
  ShmExisting e;
  e.path = "/dev/shm" + name;
  const int fd = ::shm_open(name.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW, 0);
  if (fd < 0) {
    if (errno != ENOENT) {
      e.kind = ShmExisting::Kind::kForeign;
      e.what = "shm_open(" + name + "): " + std::strerror(errno);
    }
    return e;
  }
  e.kind = ShmExisting::Kind::kForeign;
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    e.what = std::string("fstat: ") + std::strerror(errno);
    ::close(fd);
    return e;
  }
  const auto bytes = static_cast<std::uint64_t>(st.st_size);
  if (!S_ISREG(st.st_mode)) {
    e.what = S_ISDIR(st.st_mode) ? "a directory" : "not a regular file";
  } else if (st.st_uid != ::geteuid()) {
    e.what = "owned by uid " + std::to_string(st.st_uid) + ", not this user (uid " +
             std::to_string(::geteuid()) + ")";
  } else if (bytes < sizeof(ShmHeader)) {
    e.what = std::to_string(bytes) + " bytes, smaller than a segment header (" +
             std::to_string(sizeof(ShmHeader)) + ")";
  } else {
    void* p = ::mmap(nullptr, sizeof(ShmHeader), PROT_READ, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
      e.what = std::string("mmap: ") + std::strerror(errno);
    } else {
      const auto* h = static_cast<const ShmHeader*>(p);
      if (h->magic != kShmMagic) {
        e.what = std::to_string(bytes) + " bytes, magic " + hex32(h->magic) +
                 " where a hapticd segment has " + hex32(kShmMagic);
      } else {
        e.kind = ShmExisting::Kind::kHapticd;
        e.server_pid = h->server_pid.load(std::memory_order_acquire);
        e.server_heartbeat_ns = h->server_heartbeat_ns.load(std::memory_order_acquire);
      }
      ::munmap(p, sizeof(ShmHeader));
    }
  }
  ::close(fd);
  return e;
}

Result<ShmServer> ShmServer::create(const std::string& name) {
  if (name.size() < 2 || name[0] != '/' || name.find('/', 1) != std::string::npos)
    return Error{"shm name '" + name + "' must be '/' followed by a name without '/'"};
  const ShmExisting existing = inspectShm(name);
  if (existing.kind == ShmExisting::Kind::kForeign)
    return Error{existing.path + " is not a hapticd segment (" + existing.what +
                 "): left as it is"};
  if (existing.kind == ShmExisting::Kind::kHapticd)
    ::shm_unlink(name.c_str());  // a segment the caller found stale
  const int fd = ::shm_open(name.c_str(), O_CREAT | O_EXCL | O_RDWR | O_CLOEXEC, 0600);
  if (fd < 0)
    return Error{"shm_open(" + name + "): " + std::strerror(errno)};
  if (::ftruncate(fd, static_cast<off_t>(kSegmentBytes)) != 0) {
    const int e = errno;
    ::close(fd);
    ::shm_unlink(name.c_str());
    return Error{"shm " + name + ": ftruncate: " + std::strerror(e)};
  }
  void* base = ::mmap(nullptr, kSegmentBytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (base == MAP_FAILED) {
    ::shm_unlink(name.c_str());
    return Error{"shm " + name + ": mmap: " + std::strerror(errno)};
  }
  // the pages are zero; construct the atomics in place
  auto* h = new (base) ShmHeader{};
  h->segment_bytes = kSegmentBytes;
  h->state_offset = kStateOffset;
  h->state_bytes = sizeof(ShmState);
  h->ring_offset = kRingOffset;
  h->ring_slots = kShmRingSlots;
  h->slot_bytes = sizeof(ShmCommand);
  h->session_base = randomU64() & ~0xffffffffull;
  h->server_pid.store(static_cast<std::uint64_t>(::getpid()));
  new (stateBlock(base)) ShmStateBlock{};
  new (ring(base)) ShmRing{};
  h->major = kShmMajor;
  h->minor = kShmMinor;
  std::atomic_thread_fence(std::memory_order_release);
  h->magic = kShmMagic;  // last: a client that sees the magic sees a complete header
  ShmServer s;
  s.name_ = name;
  s.base_ = base;
  s.size_ = kSegmentBytes;
  return s;
}

ShmServer::ShmServer(ShmServer&& o) noexcept
    : name_(std::move(o.name_)), base_(o.base_), size_(o.size_) {
  o.base_ = nullptr;
}

ShmServer::~ShmServer() {
  if (!base_)
    return;
  ::munmap(base_, size_);
  ::shm_unlink(name_.c_str());
}

void ShmServer::publish(const ShmState& s) noexcept {
  stateBlock(base_)->write(s);
}

bool ShmServer::popCommand(ShmCommandEvent& out) noexcept {
  ShmRing* r = ring(base_);
  ShmHeader* h = header(base_);
  SpscRingRef<ShmCommand> q(r->indices, r->slots, kShmRingSlots);
  for (;;) {
    if (const std::uint64_t skipped = q.resync()) {  // a broken producer
      h->commands_refused.fetch_add(skipped, std::memory_order_relaxed);
      return false;
    }
    ShmCommand c;
    if (!q.pop(c))
      return false;
    bool ok = c.kind >= 1 && c.kind <= 3;
    if (ok && c.kind == 1) {
      ok = finiteAll(c.X_WT, 7) && finiteAll(c.v_W, 3) && finiteAll(c.w_W, 3);
      const double n = std::sqrt(c.X_WT[3] * c.X_WT[3] + c.X_WT[4] * c.X_WT[4] +
                                 c.X_WT[5] * c.X_WT[5] + c.X_WT[6] * c.X_WT[6]);
      ok = ok && std::fabs(n - 1.0) <= kQuatNormTolerance;
    }
    if (!ok) {
      h->commands_refused.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    out.kind = static_cast<ShmCommandEvent::Kind>(c.kind);
    out.session_id = h->session_base + c.generation;
    out.sequence = c.sequence;
    out.timestamp_ns = c.timestamp_ns;
    for (int i = 0; i < 3; ++i)
      out.pose.X_WT.p[static_cast<std::size_t>(i)] = c.X_WT[i];
    for (int i = 0; i < 4; ++i)
      out.pose.X_WT.q[static_cast<std::size_t>(i)] = c.X_WT[3 + i];
    for (int i = 0; i < 3; ++i) {
      out.pose.v_W[static_cast<std::size_t>(i)] = c.v_W[i];
      out.pose.w_W[static_cast<std::size_t>(i)] = c.w_W[i];
    }
    out.pose.buttons = static_cast<std::uint32_t>(c.buttons);
    return true;
  }
}

void ShmServer::beat(std::uint64_t now_ns) noexcept {
  header(base_)->server_heartbeat_ns.store(now_ns, std::memory_order_release);
}

bool ShmServer::clientAlive(std::uint64_t now_ns, std::uint64_t timeout_ns) const noexcept {
  const ShmHeader* h = header(base_);
  if (h->client_pid.load(std::memory_order_acquire) == 0)
    return false;
  const std::uint64_t t = h->client_heartbeat_ns.load(std::memory_order_acquire);
  return t != 0 && now_ns - t <= timeout_ns;
}

bool ShmServer::clientAttached() const noexcept {
  return header(base_)->client_pid.load(std::memory_order_acquire) != 0;
}

std::uint64_t ShmServer::commandsRefused() const noexcept {
  return header(base_)->commands_refused.load(std::memory_order_relaxed);
}

// ---- client --------------------------------------------------------------------------------

Result<ShmClient> ShmClient::map(const std::string& name, bool read_only) {
  const int fd = ::shm_open(name.c_str(), (read_only ? O_RDONLY : O_RDWR) | O_CLOEXEC, 0);
  if (fd < 0)
    return Error{"shm " + name + ": " + std::strerror(errno) +
                 " (is hapticd running with shared memory on?)"};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || static_cast<std::size_t>(st.st_size) < kSegmentBytes) {
    ::close(fd);
    return Error{"shm " + name + ": segment too small for this version"};
  }
  void* base = ::mmap(nullptr, kSegmentBytes, read_only ? PROT_READ : PROT_READ | PROT_WRITE,
                      MAP_SHARED, fd, 0);
  ::close(fd);
  if (base == MAP_FAILED)
    return Error{"shm " + name + ": mmap: " + std::strerror(errno)};
  ShmClient c;
  c.base_ = base;
  c.size_ = kSegmentBytes;
  c.read_only_ = true;  // until the header is checked: a refused mapping writes nothing
  const ShmHeader* h = header(base);
  const std::uint32_t magic = h->magic;
  std::atomic_thread_fence(std::memory_order_acquire);
  if (magic != kShmMagic)
    return Error{"shm " + name + ": not a hapticd segment (bad magic)"};
  if (h->major != kShmMajor)
    return Error{"shm " + name + ": layout major version " + std::to_string(h->major) +
                 ", this build speaks " + std::to_string(kShmMajor)};
  if (h->segment_bytes != kSegmentBytes || h->state_offset != kStateOffset ||
      h->ring_offset != kRingOffset || h->ring_slots != kShmRingSlots ||
      h->state_bytes < sizeof(ShmState) || h->slot_bytes != sizeof(ShmCommand))
    return Error{"shm " + name + ": layout sizes differ from this build's"};
  c.read_only_ = read_only;
  return c;
}

Result<ShmClient> ShmClient::attach(const std::string& name, std::uint64_t takeover_after_ns) {
  auto mapped = map(name, false);
  if (!mapped)
    return mapped.error();
  ShmClient c = std::move(mapped.value());
  ShmHeader* h = header(c.base_);
  const std::uint64_t pid = h->client_pid.load(std::memory_order_acquire);
  if (pid != 0) {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    const std::uint64_t now = static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000ull +
                              static_cast<std::uint64_t>(ts.tv_nsec);
    const std::uint64_t beat = h->client_heartbeat_ns.load(std::memory_order_acquire);
    if (beat != 0 && now - beat < takeover_after_ns) {
      c.read_only_ = true;  // not attached: its destructor must not clear the other's pid
      return Error{"shm " + name + ": another commanding client (pid " + std::to_string(pid) +
                   ") is attached and alive (read-only readers such as watch and record may "
                   "attach beside it)"};
    }
  }
  h->client_pid.store(static_cast<std::uint64_t>(::getpid()), std::memory_order_release);
  c.generation_ = h->client_generation.fetch_add(1, std::memory_order_acq_rel) + 1;
  return c;
}

Result<ShmClient> ShmClient::attachReader(const std::string& name) {
  return map(name, true);
}

ShmClient::ShmClient(ShmClient&& o) noexcept
    : base_(o.base_),
      size_(o.size_),
      generation_(o.generation_),
      sequence_(o.sequence_),
      read_only_(o.read_only_) {
  o.base_ = nullptr;
}

ShmClient::~ShmClient() {
  if (!base_)
    return;
  if (!read_only_) {
    ShmHeader* h = header(base_);
    std::uint64_t pid = static_cast<std::uint64_t>(::getpid());
    h->client_pid.compare_exchange_strong(pid, 0);
  }
  ::munmap(base_, size_);
}

bool ShmClient::readState(ShmState& out, int max_tries) const noexcept {
  return stateBlock(base_)->tryRead(out, max_tries);
}

bool ShmClient::push(ShmCommand c) noexcept {
  if (read_only_)
    return false;
  ShmRing* r = ring(base_);
  c.generation = generation_;
  return SpscRingRef<ShmCommand>(r->indices, r->slots, kShmRingSlots).push(c);
}

bool ShmClient::pushPose(const PoseCommand& cmd,
                         std::uint64_t now_ns,
                         std::uint64_t* sequence) noexcept {
  ShmCommand c{};
  c.kind = 1;
  c.sequence = ++sequence_;
  c.timestamp_ns = now_ns;
  for (std::size_t i = 0; i < 3; ++i)
    c.X_WT[i] = cmd.X_WT.p[i];
  for (std::size_t i = 0; i < 4; ++i)
    c.X_WT[3 + i] = cmd.X_WT.q[i];
  for (std::size_t i = 0; i < 3; ++i) {
    c.v_W[i] = cmd.v_W[i];
    c.w_W[i] = cmd.w_W[i];
  }
  c.buttons = cmd.buttons;
  if (sequence)
    *sequence = c.sequence;
  return push(c);
}

bool ShmClient::pushControl(std::uint64_t kind, std::uint64_t now_ns) noexcept {
  ShmCommand c{};
  c.kind = kind;
  c.sequence = ++sequence_;
  c.timestamp_ns = now_ns;
  c.X_WT[6] = 1.0;
  return push(c);
}

bool ShmClient::pushArm(std::uint64_t now_ns) noexcept {
  return pushControl(2, now_ns);
}

bool ShmClient::pushDisarm(std::uint64_t now_ns) noexcept {
  return pushControl(3, now_ns);
}

void ShmClient::beat(std::uint64_t now_ns) noexcept {
  if (read_only_)
    return;
  header(base_)->client_heartbeat_ns.store(now_ns, std::memory_order_release);
}

bool ShmClient::serverAlive(std::uint64_t now_ns, std::uint64_t timeout_ns) const noexcept {
  const std::uint64_t t = header(base_)->server_heartbeat_ns.load(std::memory_order_acquire);
  return t != 0 && now_ns - t <= timeout_ns;
}

std::uint64_t ShmClient::sessionId() const noexcept {
  return header(base_)->session_base + generation_;
}

}  // namespace hapticd::proto
