#include "daemon/record_writer.h"

#include <cerrno>
#include <cstring>
#include <thread>

namespace hapticd::daemon {

Result<std::unique_ptr<RecordWriter>> RecordWriter::open(ServoLoop& loop,
                                                         const std::string& record_path,
                                                         const std::string& bodies_path) {
  std::unique_ptr<RecordWriter> w(new RecordWriter(loop));
  w->record_path_ = record_path;
  w->bodies_path_ = bodies_path;
  if (!record_path.empty()) {
    w->record_ = std::fopen(record_path.c_str(), "w");
    if (w->record_ == nullptr)
      return Error{"--record " + record_path + ": cannot create: " + std::strerror(errno)};
    std::fputs(
        "tick,t,dev_px,dev_py,dev_pz,dev_qx,dev_qy,dev_qz,dev_qw,prx_px,prx_py,prx_pz,prx_qx,"
        "prx_qy,prx_qz,prx_qw,fx,fy,fz,tx,ty,tz,contacts,max_penetration,pairs_tested,"
        "pairs_skipped,tick_ns\n",
        w->record_);
  }
  if (!bodies_path.empty()) {
    w->bodies_ = std::fopen(bodies_path.c_str(), "w");
    if (w->bodies_ == nullptr)
      return Error{"--record-bodies " + bodies_path + ": cannot create: " + std::strerror(errno)};
    std::fputs("tick,t,body,px,py,pz,qx,qy,qz,qw\n", w->bodies_);
  }
  return w;
}

RecordWriter::~RecordWriter() {
  stop_ = true;
  thread_.join();
  if (record_ != nullptr)
    std::fclose(record_);
  if (bodies_ != nullptr)
    std::fclose(bodies_);
}

void RecordWriter::setBodyNames(std::uint64_t generation, std::vector<std::string> names) {
  std::lock_guard<std::mutex> lock(names_mutex_);
  names_[generation] = std::move(names);
}

Result<bool> RecordWriter::start() {
  if (record_ == nullptr && bodies_ == nullptr)
    return true;
  return thread_.start("hapticd-record", std::size_t{256} * 1024, [this] { run(); });
}

bool RecordWriter::drainOnce() {
  bool any = false;
  RecordRow r;
  for (int i = 0; i < 4096 && loop_.popRecord(r); ++i) {
    any = true;
    if (record_ == nullptr)
      continue;
    const auto& d = r.X_W_device;
    const auto& p = r.X_W_proxy;
    const int n = std::fprintf(
        record_,
        "%llu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
        "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%u,%.17g,%u,%u,%lld\n",
        static_cast<unsigned long long>(r.tick), r.t_s, d.translation.x, d.translation.y,
        d.translation.z, d.rotation.x, d.rotation.y, d.rotation.z, d.rotation.w, p.translation.x,
        p.translation.y, p.translation.z, p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w,
        r.force_n.x, r.force_n.y, r.force_n.z, r.torque_nm.x, r.torque_nm.y, r.torque_nm.z,
        r.contacts, r.max_penetration_m, r.pairs_tested, r.pairs_skipped,
        static_cast<long long>(r.tick_ns));
    if (n < 0)
      write_failed_ = true;
    ++rows_;
  }
  BodyRow b;
  for (int i = 0; i < 16384 && loop_.popBody(b); ++i) {
    any = true;
    if (bodies_ == nullptr)
      continue;
    std::string name;
    {
      std::lock_guard<std::mutex> lock(names_mutex_);
      auto it = names_.find(b.generation);
      if (it != names_.end() && b.body < it->second.size())
        name = it->second[b.body];
    }
    if (name.empty())
      name = "body" + std::to_string(b.body);
    const auto& x = b.X_WB;
    const int n = std::fprintf(bodies_, "%llu,%.17g,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                               static_cast<unsigned long long>(b.tick), b.t_s, name.c_str(),
                               x.translation.x, x.translation.y, x.translation.z, x.rotation.x,
                               x.rotation.y, x.rotation.z, x.rotation.w);
    if (n < 0)
      write_failed_ = true;
  }
  return any;
}

void RecordWriter::run() {
  for (;;) {
    const bool stopping = stop_.load();
    const bool any = drainOnce();
    if (stopping && !any)
      break;
    if (!any)
      std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
}

Result<bool> RecordWriter::finish() {
  stop_ = true;
  thread_.join();
  while (drainOnce()) {
  }
  bool ok = !write_failed_.load();
  if (record_ != nullptr && std::fclose(record_) != 0)
    ok = false;
  if (bodies_ != nullptr && std::fclose(bodies_) != 0)
    ok = false;
  record_ = bodies_ = nullptr;
  if (!ok)
    return Error{"writing the record files failed (" + record_path_ + " " + bodies_path_ + ")"};
  return true;
}

}  // namespace hapticd::daemon
