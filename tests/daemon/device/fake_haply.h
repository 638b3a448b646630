#pragma once
// A fake Haply Inverse Service for the haply backend's tests: a WebSocket server (Boost.Beast) on
// 127.0.0.1 at an ephemeral port that speaks the simulation channel as the 3.x JSON format
// describes it (daemon/device/haply_protocol.h, docs/devices.md): the device list on connecting,
// then one state message per message received. One Inverse3 and optionally one VerseGrip (wired:
// `verse_grip` with one `button`; wireless: `wireless_verse_grip` with buttons a, b, c). Scripted
// from the test (any thread): move, turn, press buttons, report an error, fall silent, drop the
// Inverse3 from its list, disconnect and come back. It records every set_cursor_force it
// receives. Its own thread runs the server.
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace hapticd::testing {

class FakeHaply {
 public:
  struct Options {
    bool grip = true;
    bool wireless = false;
    std::string type = "inverse3";
    std::string handedness = "right";
    std::string id = "049D";
  };
  FakeHaply();
  explicit FakeHaply(const Options& options);
  ~FakeHaply();
  FakeHaply(const FakeHaply&) = delete;
  FakeHaply& operator=(const FakeHaply&) = delete;

  std::uint16_t port() const;
  std::string url() const;  ///< ws://127.0.0.1:PORT

  /// The cursor (Haply's frame: x right, y forward, z up; m, m/s).
  void move(const std::array<double, 3>& position_m, const std::array<double, 3>& velocity = {});
  /// The grip's orientation (x, y, z, w; Haply's frame).
  void turn(const std::array<double, 4>& xyzw);
  void press(bool a, bool b = false, bool c = false);
  /// The Inverse3's status reports an error (`"error": "..."`, `"ready": false`) while on.
  void reportError(bool on);
  /// Stops answering (the connection stays open) while on.
  void silent(bool on);
  /// Lists no Inverse3 in its state messages while on.
  void dropInverse3(bool on);
  /// Closes the connection now and closes every new one at once until comeBack().
  void disconnect();
  void comeBack();

  /// Every set_cursor_force received (N, Haply's frame), in order.
  std::vector<std::array<double, 3>> forces() const;
  std::uint64_t forceCount() const;
  /// Messages received that were not a set_cursor_force for its Inverse3.
  std::uint64_t otherMessages() const;
  /// WebSocket connections accepted while up.
  std::uint64_t connections() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Waits (bounded: 5 s; never a timing assertion) until `done`, for what the device's I/O thread
/// and the fake's thread do in their own time; returns `done()`.
inline bool eventually(const std::function<bool()>& done) {
  for (int i = 0; i < 5000 && !done(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return done();
}

}  // namespace hapticd::testing
