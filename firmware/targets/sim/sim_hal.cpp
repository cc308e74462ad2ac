#include "sim_hal.hpp"

#include <linux/can.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>

#include "tonus/protocol/candump.hpp"

namespace tonus::sim {

namespace {

class SyntheticSource final : public FrameSource {
 public:
  explicit SyntheticSource(const fw::SynthSpec& spec) : gen_(spec) {}
  [[nodiscard]] fw::FrontEnd front_end() const override { return gen_.front_end(); }
  [[nodiscard]] float sample_rate_hz() const override { return gen_.spec().sample_rate_hz; }
  [[nodiscard]] std::size_t total_frames() const override { return gen_.total_frames(); }
  std::size_t generate(std::span<std::int16_t> out, std::size_t frames) override { return gen_.generate(out, frames); }
  [[nodiscard]] bool lose_block(std::size_t first, std::size_t count) const override {
    return gen_.lose_block(first, count);
  }

 private:
  fw::SyntheticEmg gen_;
};

class RecordingSource final : public FrameSource {
 public:
  explicit RecordingSource(Recording rec) : rec_(std::move(rec)) {}
  [[nodiscard]] fw::FrontEnd front_end() const override { return rec_.front_end; }
  [[nodiscard]] float sample_rate_hz() const override { return rec_.sample_rate_hz; }
  [[nodiscard]] std::size_t total_frames() const override { return rec_.frames.size(); }
  std::size_t generate(std::span<std::int16_t> out, std::size_t frames) override {
    std::size_t n = 0;
    for (; n < frames && pos_ < rec_.frames.size() && (n + 1) * fw::kChannels <= out.size(); ++n, ++pos_) {
      for (std::size_t ch = 0; ch < fw::kChannels; ++ch) out[n * fw::kChannels + ch] = rec_.frames[pos_][ch];
    }
    return n;
  }
  [[nodiscard]] bool lose_block(std::size_t, std::size_t) const override { return false; }

 private:
  Recording rec_;
  std::size_t pos_ = 0;
};

// SocketCAN layout <-> the protocol's transport-neutral frame.
can_frame to_socketcan(const proto::CanFrame& f) {
  can_frame out{};
  out.can_id = f.id & ((f.flags & proto::CanFrame::kExtended) != 0 ? CAN_EFF_MASK : CAN_SFF_MASK);
  if ((f.flags & proto::CanFrame::kExtended) != 0) out.can_id |= CAN_EFF_FLAG;
  if ((f.flags & proto::CanFrame::kRemote) != 0) out.can_id |= CAN_RTR_FLAG;
  if ((f.flags & proto::CanFrame::kErrorFrame) != 0) out.can_id |= CAN_ERR_FLAG;
  out.len = f.dlc;
  std::memcpy(out.data, f.data.data(), f.dlc);
  return out;
}

proto::CanFrame from_socketcan(const can_frame& f) {
  proto::CanFrame out{};
  const bool ext = (f.can_id & CAN_EFF_FLAG) != 0;
  out.id = f.can_id & (ext ? CAN_EFF_MASK : CAN_SFF_MASK);
  if (ext) out.flags |= proto::CanFrame::kExtended;
  if ((f.can_id & CAN_RTR_FLAG) != 0) out.flags |= proto::CanFrame::kRemote;
  if ((f.can_id & CAN_ERR_FLAG) != 0) out.flags |= proto::CanFrame::kErrorFrame;
  out.dlc = f.len > 8 ? 8 : f.len;
  std::memcpy(out.data.data(), f.data, out.dlc);
  return out;
}

void log_frame(std::FILE* file, const SimClock& clock, const proto::CanFrame& frame) {
  if (file == nullptr) return;
  proto::candump::Record rec{};
  rec.time_us = clock.log_time_us();
  proto::candump::set_iface(rec, "vcan0");
  rec.frame = frame;
  std::array<char, proto::candump::kMaxLine + 1> line{};
  std::size_t n = 0;
  if (proto::candump::format(rec, line, n) == proto::Error::ok) std::fwrite(line.data(), 1, n, file);
}

}  // namespace

std::unique_ptr<FrameSource> make_synthetic_source(const fw::SynthSpec& spec) {
  return std::make_unique<SyntheticSource>(spec);
}
std::unique_ptr<FrameSource> make_recording_source(Recording rec) {
  return std::make_unique<RecordingSource>(std::move(rec));
}

std::uint64_t SimClock::now_us() const {
  if (!realtime_) return since_restart(virtual_us_);
  const auto d = std::chrono::steady_clock::now() - start_;
  return since_restart(
      from_elapsed_us(static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(d).count())));
}

std::uint64_t SimClock::log_time_us() const {
  if (!realtime_) return unix_start_us_ + virtual_us_;
  const auto d = std::chrono::steady_clock::now() - start_;
  return unix_start_us_ + static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(d).count());
}

void SimClock::restart() {
  if (!realtime_) {
    restart_base_us_ = virtual_us_;
    return;
  }
  const auto d = std::chrono::steady_clock::now() - start_;
  restart_base_us_ =
      from_elapsed_us(static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::microseconds>(d).count()));
}

void SimClock::set_host_mapping(std::int64_t offset_us, double drift_ppm) {
  mapped_ = true;
  offset_us_ = offset_us;
  drift_ppm_ = drift_ppm;
}

std::uint64_t SimClock::from_elapsed_us(std::uint64_t elapsed_us) const {
  if (!mapped_) return elapsed_us;
  const auto start_us = std::chrono::duration_cast<std::chrono::microseconds>(start_.time_since_epoch()).count();
  const double host_us = static_cast<double>(start_us) + static_cast<double>(elapsed_us);
  const double device_us = static_cast<double>(offset_us_) + host_us * (1.0 + drift_ppm_ * 1e-6);
  return device_us > 0.0 ? static_cast<std::uint64_t>(std::llround(device_us)) : 0;  // a clock never reads below 0
}

SimSystem::SimSystem() {
  // Differs between processes with near certainty; the band uses a retained counter instead.
  std::random_device rd;
  const auto now = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
  const std::uint64_t mixed = rd() ^ static_cast<std::uint64_t>(::getpid()) ^ now ^ (now >> 17U);
  epoch_ = static_cast<std::uint8_t>(mixed % 255U + 1U);
}

bool SimSampler::start(std::uint16_t rate_hz) {
  // The source has one rate; the core only asks for rates its front end supports.
  running_ = static_cast<float>(rate_hz) == source_.sample_rate_hz();
  ready_ = {false, false};
  return running_;
}

std::uint64_t SimSampler::next_block_start_us() const {
  return static_cast<std::uint64_t>(static_cast<double>(frames_done_) * 1e6 /
                                    static_cast<double>(source_.sample_rate_hz()));
}

bool SimSampler::produce() {
  hal::SampleBlock& b = halves_[write_half_];
  const std::uint64_t start = next_block_start_us();
  const std::size_t n = source_.generate(b.samples, block_frames_);
  if (n == 0) return false;
  const bool lost = source_.lose_block(frames_done_, n) || !running_;
  frames_done_ += n;
  clock_.advance_to(next_block_start_us());
  const std::uint32_t seq = sequence_++;
  if (lost) {
    ++dropped_;
    return true;
  }
  if (ready_[write_half_]) ++dropped_;  // the core never released this half: the DMA overwrote it
  b.sequence = seq;
  b.first_sample_us = clock_.since_restart(clock_.realtime() ? clock_.from_elapsed_us(start) : start);
  b.frames = static_cast<std::uint16_t>(n);
  ready_[write_half_] = true;
  if (ready_[read_half_] == false) read_half_ = write_half_;
  write_half_ ^= 1U;
  return true;
}

const hal::SampleBlock* SimSampler::acquire() {
  if (!ready_[read_half_]) return nullptr;
  return &halves_[read_half_];
}

void SimSampler::release() {
  ready_[read_half_] = false;
  read_half_ ^= 1U;
}

FlashStorage::FlashStorage(std::string path) : path_(std::move(path)), bytes_(kSize, 0xFF) {
  if (path_.empty()) return;
  std::ifstream in(path_, std::ios::binary);
  if (!in) return;
  in.read(reinterpret_cast<char*>(bytes_.data()), static_cast<std::streamsize>(bytes_.size()));
}

bool FlashStorage::read(std::size_t offset, std::span<std::uint8_t> out) {
  if (offset > bytes_.size() || out.size() > bytes_.size() - offset) return false;
  std::memcpy(out.data(), bytes_.data() + offset, out.size());
  return true;
}

bool FlashStorage::erase(std::size_t sector) {
  if (sector >= kSectors) return false;
  const auto first = bytes_.begin() + static_cast<std::ptrdiff_t>(sector * kSectorSize);
  std::fill(first, first + static_cast<std::ptrdiff_t>(kSectorSize), std::uint8_t{0xFF});
  persist();
  return true;
}

bool FlashStorage::program(std::size_t offset, std::span<const std::uint8_t> data) {
  if (offset > bytes_.size() || data.size() > bytes_.size() - offset) return false;
  // Flash can only clear bits: programming over written bytes ANDs them.
  for (std::size_t k = 0; k < data.size(); ++k) bytes_[offset + k] &= data[k];
  persist();
  return true;
}

void FlashStorage::persist() {
  if (path_.empty()) return;
  std::ofstream out(path_, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes_.data()), static_cast<std::streamsize>(bytes_.size()));
}

SeqpacketEndpoint::~SeqpacketEndpoint() {
  if (fd_ >= 0) ::close(fd_);
  if (listen_fd_ >= 0) {
    ::close(listen_fd_);
    ::unlink(path_.c_str());
  }
}

bool SeqpacketEndpoint::adopt_fd(int fd, std::string& error) {
  int type = 0;
  socklen_t len = sizeof type;
  if (::getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &len) != 0 || type != SOCK_SEQPACKET) {
    error = "fd " + std::to_string(fd) + " is not a SOCK_SEQPACKET socket";
    return false;
  }
  fd_ = fd;
  return true;
}

bool SeqpacketEndpoint::listen_on(const std::string& path, std::string& error) {
  sockaddr_un addr{};
  if (path.size() >= sizeof addr.sun_path) {
    error = "socket path too long: " + path;
    return false;
  }
  listen_fd_ = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  addr.sun_family = AF_UNIX;
  std::memcpy(addr.sun_path, path.c_str(), path.size());
  ::unlink(path.c_str());
  if (listen_fd_ < 0 || ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      ::listen(listen_fd_, 1) != 0) {
    error = "cannot listen on " + path + ": " + std::strerror(errno);
    return false;
  }
  path_ = path;
  return true;
}

bool SeqpacketEndpoint::connected() {
  if (fd_ < 0 && listen_fd_ >= 0) {
    fd_ = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd_ >= 0) peer_gone_ = false;
  }
  return fd_ >= 0;
}

void SeqpacketEndpoint::drop_peer() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  peer_gone_ = true;
}

bool SeqpacketEndpoint::send(std::span<const std::uint8_t> bytes) {
  if (!connected()) return false;
  const int flags = MSG_NOSIGNAL | (blocking_send_ ? 0 : MSG_DONTWAIT);
  for (;;) {
    const ssize_t n = ::send(fd_, bytes.data(), bytes.size(), flags);
    if (n == static_cast<ssize_t>(bytes.size())) return true;
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return false;  // host not reading: drop
    drop_peer();
    return false;
  }
}

std::size_t SeqpacketEndpoint::receive(std::span<std::uint8_t> out) {
  if (!connected()) return 0;
  const ssize_t n = ::recv(fd_, out.data(), out.size(), MSG_DONTWAIT | MSG_TRUNC);
  if (n == 0) {
    drop_peer();  // orderly shutdown of the host side
    return 0;
  }
  if (n < 0) {
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) drop_peer();
    return 0;
  }
  return static_cast<std::size_t>(n);
}

bool SeqpacketHid::receive_output(proto::hid::Report& report, std::size_t& length) {
  report.fill(0);
  // MSG_TRUNC makes an oversized datagram visible by its real length.
  const std::size_t n = ep_.receive(report);
  if (n == 0) return false;
  length = n;
  return true;
}

bool SeqpacketCan::send(const proto::CanFrame& frame) {
  const can_frame f = to_socketcan(frame);
  log(frame);
  if (!ep_.send(std::span(reinterpret_cast<const std::uint8_t*>(&f), sizeof f))) return false;
  ++sent_;
  return true;
}

bool SeqpacketCan::receive(proto::CanFrame& frame) {
  for (;;) {
    can_frame f{};
    const std::size_t n = ep_.receive(std::span(reinterpret_cast<std::uint8_t*>(&f), sizeof f));
    if (n == 0) return false;
    if (n != sizeof f) continue;  // not a classic CAN frame (CAN FD or garbage): a real CAN_RAW socket drops it too
    frame = from_socketcan(f);
    log(frame);
    return true;
  }
}

void SeqpacketCan::log(const proto::CanFrame& frame) { log_frame(candump_, clock_, frame); }

bool LogOnlyCan::send(const proto::CanFrame& frame) {
  log_frame(candump_, clock_, frame);
  return true;
}

}  // namespace tonus::sim
