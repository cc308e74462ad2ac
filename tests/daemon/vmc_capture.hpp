// What tonusd sends, as an avatar engine receives it: a UDP socket on
// 127.0.0.1 (an ephemeral port) whose datagrams are parsed by liblo itself
// (lo_server_dispatch_data on a server bound to a Unix socket path, so
// nothing listens on the network), every message kept with its arrival time.
#pragma once

#include <arpa/inet.h>
#include <lo/lo.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace tonus::test {

struct OscMessage {
  std::string path;
  std::string types;
  std::string text;             // the first string argument, if any
  std::vector<double> numbers;  // every int and float argument, in order
  std::int64_t arrival_us = 0;  // steady clock
};

inline std::int64_t steady_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

class VmcCapture {
 public:
  VmcCapture() {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) fd_ = -1;
    const int buffer_bytes = 8 << 20;  // a replay as fast as it goes sends bursts: lose none
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &buffer_bytes, sizeof buffer_bytes);
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    unix_path_ = "/tmp/tonus-vmc-capture-" + std::to_string(::getpid()) + "-" + std::to_string(port_);
    ::unlink(unix_path_.c_str());
    server_ = lo_server_new_with_proto(unix_path_.c_str(), LO_UNIX, nullptr);
    lo_server_add_method(server_, nullptr, nullptr, &VmcCapture::on_message, this);
    thread_ = std::thread([this] { run(); });
  }
  ~VmcCapture() {
    stop_.store(true);
    thread_.join();
    lo_server_free(server_);
    ::unlink(unix_path_.c_str());
    ::close(fd_);
  }
  VmcCapture(const VmcCapture&) = delete;
  VmcCapture& operator=(const VmcCapture&) = delete;

  [[nodiscard]] int port() const { return port_; }
  [[nodiscard]] std::vector<OscMessage> messages() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return messages_;
  }
  // Every datagram's bytes, in arrival order.
  [[nodiscard]] std::vector<std::vector<unsigned char>> raw() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return raw_;
  }
  [[nodiscard]] std::size_t datagrams() const { return datagrams_.load(); }
  [[nodiscard]] std::size_t max_datagram() const { return max_datagram_.load(); }
  [[nodiscard]] std::size_t unparsed() const { return unparsed_.load(); }

 private:
  static int on_message(const char* path, const char* types, lo_arg** argv, int argc, lo_message /*m*/, void* self) {
    auto* c = static_cast<VmcCapture*>(self);
    OscMessage msg;
    msg.path = path;
    msg.types = types;
    msg.arrival_us = c->now_us_;
    // liblo's argument pointers are only 4-byte aligned (lo_arg wants 8): read the bytes.
    for (int i = 0; i < argc; ++i) {
      const void* p = argv[i];
      switch (types[i]) {
        case 's': msg.text = static_cast<const char*>(p); break;
        case 'f': {
          float f = 0;
          std::memcpy(&f, p, sizeof f);
          msg.numbers.push_back(static_cast<double>(f));
          break;
        }
        case 'i': {
          std::int32_t v = 0;
          std::memcpy(&v, p, sizeof v);
          msg.numbers.push_back(v);
          break;
        }
        case 'd': {
          double v = 0;
          std::memcpy(&v, p, sizeof v);
          msg.numbers.push_back(v);
          break;
        }
        default: break;
      }
    }
    const std::lock_guard<std::mutex> lock(c->mutex_);
    c->messages_.push_back(std::move(msg));
    return 0;
  }

  void run() {
    std::vector<unsigned char> buf(65536);
    while (!stop_.load()) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
      if (n <= 0) continue;
      now_us_ = steady_us();
      ++datagrams_;
      if (static_cast<std::size_t>(n) > max_datagram_.load()) max_datagram_.store(static_cast<std::size_t>(n));
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        raw_.emplace_back(buf.begin(), buf.begin() + n);
      }
      if (lo_server_dispatch_data(server_, buf.data(), static_cast<std::size_t>(n)) <= 0) ++unparsed_;
    }
  }

  int fd_ = -1;
  int port_ = 0;
  std::string unix_path_;
  lo_server server_ = nullptr;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::int64_t now_us_ = 0;
  mutable std::mutex mutex_;
  std::vector<OscMessage> messages_;
  std::vector<std::vector<unsigned char>> raw_;
  std::atomic<std::size_t> datagrams_{0}, max_datagram_{0}, unparsed_{0};
};

}  // namespace tonus::test
