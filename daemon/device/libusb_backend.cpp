// The real USB backend: libusb-1.0 and the FTDI FT232's vendor requests (the requests and their
// values as documented by FTDI's application notes and used by libftdi and libnifalcon).
#include <libusb-1.0/libusb.h>

#include <algorithm>
#include <array>
#include <span>

#include "daemon/device/falcon_firmware.h"
#include "daemon/device/usb_device.h"

namespace hapticd::device {

namespace {

using namespace falcon;  // the FTDI request constants of falcon_firmware.h

constexpr std::uint8_t kFtdiRequestType = 0x40;  // vendor request, host to device
constexpr unsigned kControlTimeout_ms = 1000;
constexpr std::uint8_t kEndpointIn = 0x81;
constexpr std::uint8_t kEndpointOut = 0x02;
constexpr unsigned kBulkReadTimeout_ms = 1;
constexpr unsigned kBulkWriteTimeout_ms = 2;
constexpr int kFtdiPacket = 64;  // each USB packet from the FTDI starts with 2 modem status bytes

// The data of `got` bytes of FTDI packets into `buf` (the 2 status bytes at the start of every
// 64-byte USB packet stripped); the bytes written.
int stripFtdiStatus(const std::uint8_t* raw, int got, std::span<std::uint8_t> buf) noexcept {
  std::size_t out = 0;
  for (int off = 0; off < got; off += kFtdiPacket) {
    const int end = std::min(got, off + kFtdiPacket);
    for (int i = off + 2; i < end && out < buf.size(); ++i)
      buf[out++] = raw[i];
  }
  return static_cast<int>(out);
}

// One bulk read of FTDI packets into `raw`, their data into `buf`: the bytes written (0 on a
// timeout), -1 on a failure. No allocation (the servo thread's transport and the loader use it).
int readFtdi(libusb_device_handle* h,
             std::span<std::uint8_t, kFtdiPacket> raw,
             std::span<std::uint8_t> buf,
             unsigned timeout_ms) noexcept {
  int got = 0;
  const int rc = libusb_bulk_transfer(h, kEndpointIn, raw.data(), static_cast<int>(raw.size()),
                                      &got, timeout_ms);
  if (rc != 0 && rc != LIBUSB_ERROR_TIMEOUT)
    return -1;
  return stripFtdiStatus(raw.data(), got, buf);
}

// One bulk write of up to 64 bytes of `bytes` through `out`: the bytes sent (a timeout may send
// fewer), -1 on a failure. No allocation.
int writeFtdi(libusb_device_handle* h,
              std::span<std::uint8_t, 64> out,
              std::span<const std::uint8_t> bytes,
              unsigned timeout_ms) noexcept {
  const std::size_t n = std::min(bytes.size(), out.size());
  std::copy_n(bytes.begin(), n, out.begin());
  int sent = 0;
  const int rc =
      libusb_bulk_transfer(h, kEndpointOut, out.data(), static_cast<int>(n), &sent, timeout_ms);
  return rc == 0 || rc == LIBUSB_ERROR_TIMEOUT ? sent : -1;
}

class LibusbTransport final : public UsbTransport {
 public:
  explicit LibusbTransport(libusb_device_handle* h) : h_(h) {}
  ~LibusbTransport() override {
    libusb_release_interface(h_, 0);
    libusb_close(h_);
  }
  int read(std::span<std::uint8_t> buf) noexcept override {
    return readFtdi(h_, raw_, buf, kBulkReadTimeout_ms);
  }
  int write(std::span<const std::uint8_t> bytes) noexcept override {
    return writeFtdi(h_, out_, bytes, kBulkWriteTimeout_ms);
  }

 private:
  libusb_device_handle* h_;
  std::array<std::uint8_t, kFtdiPacket> raw_{};
  std::array<std::uint8_t, 64> out_{};
};

// the blocking link the firmware loader talks through (normal thread)
class BlockingLink final : public falcon::FtdiLink {
 public:
  explicit BlockingLink(libusb_device_handle* h) : h_(h) {}
  bool control(std::uint8_t request, std::uint16_t value) override {
    return libusb_control_transfer(h_, kFtdiRequestType, request, value, 0, nullptr, 0,
                                   kControlTimeout_ms) >= 0;
  }
  int write(std::span<const std::uint8_t> bytes, unsigned timeout_ms) override {
    std::array<std::uint8_t, 64> out{};
    return writeFtdi(h_, out, bytes, timeout_ms);
  }
  int read(std::span<std::uint8_t> buf, unsigned timeout_ms) override {
    std::array<std::uint8_t, kFtdiPacket> raw{};
    return readFtdi(h_, raw, buf, timeout_ms);
  }

 private:
  libusb_device_handle* h_;
};

class LibusbBackend final : public UsbBackend {
 public:
  explicit LibusbBackend(libusb_context* ctx) : ctx_(ctx) {}
  ~LibusbBackend() override {
    if (registered_)
      libusb_hotplug_deregister_callback(ctx_, handle_);
    libusb_exit(ctx_);
  }
  bool startHotplug(std::function<void(UsbHotplugEvent)> callback) override {
    if (!libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG))
      return false;
    callback_ = std::move(callback);
    const int rc = libusb_hotplug_register_callback(
        ctx_,
        static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
                                          LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
        static_cast<libusb_hotplug_flag>(0), falcon::kVendorId, falcon::kProductId,
        LIBUSB_HOTPLUG_MATCH_ANY, &LibusbBackend::onHotplug, this, &handle_);
    registered_ = rc == LIBUSB_SUCCESS;
    return registered_;
  }
  void handleEvents() override {
    timeval tv{0, 0};
    libusb_handle_events_timeout_completed(ctx_, &tv, nullptr);
  }
  int countFalcons() override {
    libusb_device** list = nullptr;
    const ssize_t n = libusb_get_device_list(ctx_, &list);
    int count = 0;
    for (ssize_t i = 0; i < n; ++i) {
      libusb_device_descriptor d{};
      if (libusb_get_device_descriptor(list[i], &d) == 0 && d.idVendor == falcon::kVendorId &&
          d.idProduct == falcon::kProductId)
        ++count;
    }
    if (list)
      libusb_free_device_list(list, 1);
    return count;
  }
  Result<bool> loadFirmware(std::span<const std::uint8_t> firmware) override {
    auto h = claim();
    if (!h)
      return h.error();
    BlockingLink link(h.value());
    auto r = falcon::loadFirmware(link, firmware);
    libusb_release_interface(h.value(), 0);
    libusb_close(h.value());
    return r;
  }
  Result<std::unique_ptr<UsbTransport>> open() override {
    auto claimed = claim();
    if (!claimed)
      return claimed.error();
    libusb_device_handle* h = claimed.value();
    struct Setup {
      std::uint8_t request;
      std::uint16_t value;
      const char* what;
    };
    const Setup steps[] = {
        {kFtdiReset, 0, "reset"},
        {kFtdiSetLatencyTimer, 1, "latency timer"},
        {kFtdiSetBaudRate, kFtdiBaudNormal, "baud rate"},
        {kFtdiSetData, kFtdiData8N1, "line properties"},
        {kFtdiSetFlowCtrl, 0, "flow control"},
        {kFtdiReset, kFtdiPurgeRx, "purge rx"},
        {kFtdiReset, kFtdiPurgeTx, "purge tx"},
    };
    for (const Setup& s : steps) {
      const int rc = libusb_control_transfer(h, kFtdiRequestType, s.request, s.value, 0, nullptr, 0,
                                             kControlTimeout_ms);
      if (rc < 0) {
        libusb_release_interface(h, 0);
        libusb_close(h);
        return Error{std::string("FTDI ") + s.what + " failed: " + libusb_error_name(rc)};
      }
    }
    return std::unique_ptr<UsbTransport>(std::make_unique<LibusbTransport>(h));
  }

 private:
  Result<libusb_device_handle*> claim() {
    libusb_device_handle* h =
        libusb_open_device_with_vid_pid(ctx_, falcon::kVendorId, falcon::kProductId);
    if (!h)
      return Error{"libusb_open failed (no device, or no permission)"};
    libusb_set_auto_detach_kernel_driver(h, 1);
    if (const int rc = libusb_claim_interface(h, 0); rc != 0) {
      libusb_close(h);
      return Error{std::string("cannot claim interface 0: ") + libusb_error_name(rc)};
    }
    return h;
  }

  static int LIBUSB_CALL onHotplug(libusb_context*,
                                   libusb_device*,
                                   libusb_hotplug_event event,
                                   void* user) {
    auto* self = static_cast<LibusbBackend*>(user);
    if (self->callback_)
      self->callback_(event == LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT ? UsbHotplugEvent::kLeft
                                                                : UsbHotplugEvent::kArrived);
    return 0;  // stay registered
  }

  libusb_context* ctx_;
  std::function<void(UsbHotplugEvent)> callback_;
  libusb_hotplug_callback_handle handle_{};
  bool registered_ = false;
};

}  // namespace

Result<std::unique_ptr<UsbBackend>> makeLibusbBackend() {
  libusb_context* ctx = nullptr;
  if (const int rc = libusb_init(&ctx); rc != 0)
    return Error{std::string("libusb_init failed: ") + libusb_error_name(rc)};
  return std::unique_ptr<UsbBackend>(std::make_unique<LibusbBackend>(ctx));
}

}  // namespace hapticd::device
