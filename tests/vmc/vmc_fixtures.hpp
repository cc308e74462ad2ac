// Shared by the VMC tests: the humanoid, poses within its joints, a plain UDP
// socket on loopback (a reader independent of the receiver, and a sender of
// hand-made datagrams), an independent OSC reader (liblo's message decoder,
// bundle framing walked here), and a receiver pump that stops by itself.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tonus/host/vmc/receiver.hpp"
#include "tonus/sim/math.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::vmc::test {

const sim::Model& humanoid();

// qpos0 with the root at `root_pos`, turned by `root_rot`, and a lively pose
// inside every joint's range (arms raised and bent, a knee bent, the head
// turned, the trunk leaning).
std::vector<double> lively_qpos(const sim::Vec3& root_pos, const sim::Quat& root_rot);

// A bound UDP socket on 127.0.0.1 (port chosen by the kernel).
class UdpSocket {
 public:
  UdpSocket();
  ~UdpSocket();
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  [[nodiscard]] int port() const { return port_; }
  void send_to(int port, const std::vector<unsigned char>& datagram) const;
  // Every datagram arriving within `quiet_ms` of the previous one (the first within 2 s).
  std::vector<std::vector<unsigned char>> receive_all(int quiet_ms = 200) const;

 private:
  int fd_ = -1;
  int port_ = 0;
};

// One OSC message, decoded.
struct OscMessage {
  std::string path;
  std::string types;
  std::vector<double> numbers;       // every f, d and i argument, in order
  std::vector<std::string> strings;  // every s argument, in order
  std::size_t datagram = 0;          // which datagram it came in
  bool in_bundle = false;
};

// Decodes datagrams (messages or one level of bundles); REQUIREs validity.
std::vector<OscMessage> decode_all(const std::vector<std::vector<unsigned char>>& datagrams);

// A serialised OSC message (liblo), for hand-made datagrams.
std::vector<unsigned char> osc_message(const std::string& path, const std::string& types,
                                       const std::vector<double>& numbers, const std::vector<std::string>& strings);
// A bundle of serialised messages (immediate time tag).
std::vector<unsigned char> osc_bundle(const std::vector<std::vector<unsigned char>>& elements);

// Calls receiver.receive(10) until `done` or 3 s have passed. True when done.
bool pump(VmcReceiver& receiver, const std::function<bool()>& done);

}  // namespace tonus::vmc::test
