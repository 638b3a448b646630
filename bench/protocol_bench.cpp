// Protocol benchmarks: codec cost of the largest messages, and the round trip pose command →
// state over UDP loopback and over shared memory, against a minimal echo thread that answers
// each command with a state echoing its sequence. Percentiles (p50, p99, in µs) are counters.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "protocol/messages.h"
#include "protocol/server.h"  // monotonicNs
#include "protocol/shm.h"
#include "protocol/udp.h"

namespace {

using namespace hapticd::proto;

State fullState() {
  State s;
  s.force_scale = 1.0;
  s.contacts.resize(kMaxStateContacts);
  s.bodies.resize(kMaxStateBodies);
  return s;
}

void reportPercentiles(benchmark::State& state, std::vector<std::uint64_t>& ns) {
  if (ns.empty())
    return;
  std::sort(ns.begin(), ns.end());
  auto at = [&](double q) {
    return static_cast<double>(ns[std::min(
               ns.size() - 1, static_cast<std::size_t>(q * static_cast<double>(ns.size())))]) *
           1e-3;
  };
  state.counters["p50_us"] = at(0.50);
  state.counters["p99_us"] = at(0.99);
  state.counters["max_us"] = static_cast<double>(ns.back()) * 1e-3;
}

void ProtocolEncodeState(benchmark::State& state) {
  const Message m = fullState();
  std::vector<std::uint8_t> buf(kMaxDatagramLimit);
  for (auto _ : state)
    benchmark::DoNotOptimize(encode({}, m, buf));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(kHeaderSize + payloadSize(m)));
}
BENCHMARK(ProtocolEncodeState)->Name("Protocol/Encode/StateFull");

void ProtocolDecodeState(benchmark::State& state) {
  std::vector<std::uint8_t> buf(kMaxDatagramLimit);
  buf.resize(encode({}, fullState(), buf));
  for (auto _ : state) {
    Header h;
    Message m;
    benchmark::DoNotOptimize(decode(buf, h, m));
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(buf.size()));
}
BENCHMARK(ProtocolDecodeState)->Name("Protocol/Decode/StateFull");

void ProtocolDecodePose(benchmark::State& state) {
  std::vector<std::uint8_t> buf(256);
  buf.resize(encode({}, PoseCommand{}, buf));
  for (auto _ : state) {
    Header h;
    Message m;
    benchmark::DoNotOptimize(decode(buf, h, m));
  }
}
BENCHMARK(ProtocolDecodePose)->Name("Protocol/Decode/PoseCommand");

// UDP: the client sends a PoseCommand, the echo thread decodes it and answers with a State
// (no lists) carrying the sequence; the client decodes the State.
void ProtocolRoundTripUdp(benchmark::State& state) {
  auto server_sock = UdpSocket::bind(parseAddress("127.0.0.1:0").value()).value();
  const SocketAddress server_addr = server_sock.localAddress();
  auto client_sock = UdpSocket::forPeer(server_addr).value();
  std::atomic<bool> stop{false};
  std::thread echo([&] {
    std::vector<std::uint8_t> rx(kMaxDatagramLimit), tx(kMaxDatagramLimit);
    while (!stop.load(std::memory_order_relaxed)) {
      if (!server_sock.waitReadable(10))
        continue;
      SocketAddress from;
      const Received r = server_sock.receive(rx, from);
      if (!r.got)
        continue;
      Header h;
      Message m;
      if (decode(std::span(rx.data(), r.size), h, m).code != Errc::kOk)
        continue;
      State s;
      s.last_command_sequence = h.sequence;
      Header out;
      out.sequence = h.sequence;
      const std::size_t n = encode(out, s, tx);
      server_sock.sendTo(from, std::span(tx.data(), n));
    }
  });
  std::vector<std::uint8_t> rx(kMaxDatagramLimit), tx(512);
  std::vector<std::uint64_t> ns;
  ns.reserve(1 << 20);
  std::uint64_t seq = 0;
  PoseCommand p;
  for (auto _ : state) {
    Header h;
    h.sequence = ++seq;
    const std::uint64_t t0 = monotonicNs();
    const std::size_t n = encode(h, p, tx);
    client_sock.sendTo(server_addr, std::span(tx.data(), n));
    for (;;) {
      if (!client_sock.waitReadable(1000))
        break;
      SocketAddress from;
      const Received r = client_sock.receive(rx, from);
      Header rh;
      Message m;
      if (r.got && decode(std::span(rx.data(), r.size), rh, m).code == Errc::kOk &&
          std::get<State>(m).last_command_sequence == seq)
        break;
    }
    ns.push_back(monotonicNs() - t0);
  }
  stop = true;
  echo.join();
  reportPercentiles(state, ns);
}
BENCHMARK(ProtocolRoundTripUdp)->Name("Protocol/RoundTrip/Udp")->UseRealTime()->MinTime(2.0);

// Shared memory: the client pushes a pose on the ring, the echo thread (as the servo would)
// pops it and publishes a state with its sequence; the client spins on the seqlock until it
// sees it. Both sides busy-poll (as a 1 kHz servo and a spinning client would).
void ProtocolRoundTripShm(benchmark::State& state) {
  const std::string name = "/hapticd-bench-" + std::to_string(::getpid());
  auto server = ShmServer::create(name);
  if (!server) {
    state.SkipWithError(server.error().message.c_str());
    return;
  }
  auto client = ShmClient::attach(name);
  if (!client) {
    state.SkipWithError(client.error().message.c_str());
    return;
  }
  std::atomic<bool> stop{false};
  std::thread echo([&] {
    ShmCommandEvent e;
    ShmState s{};
    while (!stop.load(std::memory_order_relaxed)) {
      if (!server.value().popCommand(e)) {
        std::this_thread::yield();
        continue;
      }
      s.last_command_sequence = e.sequence;
      server.value().publish(s);
    }
  });
  std::vector<std::uint64_t> ns;
  ns.reserve(1 << 20);
  PoseCommand p;
  ShmState s{};
  for (auto _ : state) {
    std::uint64_t seq = 0;
    const std::uint64_t t0 = monotonicNs();
    while (!client.value().pushPose(p, t0, &seq))
      std::this_thread::yield();
    for (;;) {
      if (client.value().readState(s) && s.last_command_sequence == seq)
        break;
      std::this_thread::yield();
    }
    ns.push_back(monotonicNs() - t0);
  }
  stop = true;
  echo.join();
  reportPercentiles(state, ns);
}
BENCHMARK(ProtocolRoundTripShm)->Name("Protocol/RoundTrip/Shm")->UseRealTime()->MinTime(2.0);

}  // namespace
