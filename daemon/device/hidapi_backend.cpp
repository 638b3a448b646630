// The real HID backend: hidapi's hidraw implementation.
#include <hidapi/hidapi.h>

#include <cwchar>

#include "daemon/device/hid_device.h"

namespace hapticd::device {

namespace {

std::string narrow(const wchar_t* w) {
  std::string s;
  if (!w)
    return s;
  for (; *w; ++w)
    s += (*w >= 0x20 && *w < 0x7f) ? static_cast<char>(*w) : '?';
  return s;
}

class HidapiTransport final : public HidTransport {
 public:
  explicit HidapiTransport(hid_device* dev) : dev_(dev) {}
  ~HidapiTransport() override { hid_close(dev_); }
  int readReport(std::span<std::uint8_t> buf) noexcept override {
    // a zero timeout: never waits on the servo thread
    return hid_read_timeout(dev_, buf.data(), buf.size(), 0);
  }
  int writeReport(std::span<const std::uint8_t> report) noexcept override {
    return hid_write(dev_, report.data(), report.size());
  }

 private:
  hid_device* dev_;
};

class HidapiBackend final : public HidBackend {
 public:
  HidapiBackend() : init_ok_(hid_init() == 0) {}
  std::vector<HidDeviceEntry> enumerate() override {
    std::vector<HidDeviceEntry> out;
    if (!init_ok_)
      return out;
    hid_device_info* list = hid_enumerate(0, 0);
    for (hid_device_info* d = list; d; d = d->next) {
      HidDeviceEntry e;
      e.path = d->path ? d->path : "";
      e.vendor_id = d->vendor_id;
      e.product_id = d->product_id;
      e.usage_page = d->usage_page;
      e.usage = d->usage;
      e.product = narrow(d->product_string);
      out.push_back(std::move(e));
    }
    hid_free_enumeration(list);
    return out;
  }
  Result<std::unique_ptr<HidTransport>> open(const std::string& path) override {
    if (!init_ok_)
      return Error{"hidapi failed to initialise"};
    hid_device* dev = hid_open_path(path.c_str());
    if (!dev) {
      const std::string why = narrow(hid_error(nullptr));
      return Error{why.empty() ? "hid_open_path failed (permissions? see docs/devices.md udev)"
                               : why};
    }
    return std::unique_ptr<HidTransport>(std::make_unique<HidapiTransport>(dev));
  }

 private:
  bool init_ok_;
};

}  // namespace

std::unique_ptr<HidBackend> makeHidapiBackend() {
  return std::make_unique<HidapiBackend>();
}

}  // namespace hapticd::device
