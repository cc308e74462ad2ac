#include "tonus/host/daemon/recorder.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include <fmt/format.h>

namespace tonus::daemon {
namespace {

// Writes all of `b`; an error message when the system refuses.
std::string write_all(int fd, const std::vector<std::uint8_t>& b) {
  std::size_t done = 0;
  while (done < b.size()) {
    const ssize_t n = ::write(fd, b.data() + done, b.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return std::strerror(errno);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fdatasync(fd) != 0 && errno != EINVAL) return std::strerror(errno);  // EINVAL: a pipe or a special file
  return {};
}

}  // namespace

std::unique_ptr<Recorder> Recorder::create(const std::string& path, const recording::Header& header,
                                           std::string& error) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    error = fmt::format("record: {}: {}", path, std::strerror(errno));
    return nullptr;
  }
  if (const std::string e = write_all(fd, recording::encode_header(header)); !e.empty()) {
    error = fmt::format("record: {}: {}", path, e);
    ::close(fd);
    return nullptr;
  }
  return std::unique_ptr<Recorder>(new Recorder(fd, header));
}

Recorder::Recorder(int fd, const recording::Header& header) : fd_(fd), header_(header) {
  status_.bytes = static_cast<std::uint64_t>(::lseek(fd, 0, SEEK_CUR));
}

Recorder::~Recorder() {
  stop();
  if (fd_ >= 0) ::close(fd_);
}

void Recorder::start() {
  if (thread_.joinable()) return;
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
}

void Recorder::stop() {
  {
    const std::lock_guard<std::mutex> lock(wake_mutex_);
    stop_.store(true);
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void Recorder::tick(std::int64_t now_us, std::uint64_t tick, std::uint64_t pose_hash, std::uint32_t bands,
                    std::uint32_t poses, std::uint32_t commands) {
  push(ticks_, TickRecord{now_us, tick, pose_hash, bands, poses, commands});
}

RecorderStatus Recorder::status() const {
  const std::lock_guard<std::mutex> lock(status_mutex_);
  return status_;
}

void Recorder::fail(std::string why) {
  failed_.store(true);
  const std::lock_guard<std::mutex> lock(status_mutex_);
  if (!status_.failed) {
    status_.failed = true;
    status_.error = std::move(why);
  }
}

void Recorder::run() {
  recording::Chunk chunk;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(wake_mutex_);
      wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return stop_.load(); });
    }
    const bool stopping = stop_.load();
    if (!drain(chunk, stopping) || stopping) break;
  }
}

bool Recorder::drain(recording::Chunk& chunk, bool final) {
  const auto per_chunk = static_cast<std::size_t>(std::max(1.0, header_.rate_hz));  // about a second
  TickRecord t;
  while (ticks_.try_dequeue(t)) {
    recording::TickInputs in;
    in.now_us = t.now_us;
    in.band.resize(t.bands);
    in.poses.resize(t.poses);
    in.commands.resize(t.commands);
    // The items were queued before their tick: they are there.
    for (BandSample& b : in.band) (void)band_.try_dequeue(b);
    for (PoseSample& p : in.poses) (void)poses_.try_dequeue(p);
    for (Command& c : in.commands) (void)commands_.try_dequeue(c);
    if (chunk.ticks.empty()) chunk.first_tick = t.tick;
    chunk.ticks.push_back(std::move(in));
    chunk.pose_hash = t.pose_hash;
    if (chunk.ticks.size() >= per_chunk && !write_chunk(chunk)) return false;
  }
  const bool overflowed = failed_.load() && !status().failed;
  if ((final || overflowed) && !chunk.ticks.empty() && !write_chunk(chunk)) return false;
  if (overflowed) {
    fail(fmt::format("recording stopped after tick {}: the writer fell more than {} ticks behind (a slow disk?)",
                     status().ticks, kTickQueue));
    return false;
  }
  return !failed_.load();
}

bool Recorder::write_chunk(recording::Chunk& chunk) {
  std::uint64_t v = 0;
  while (vmc_.try_dequeue(v)) chunk.vmc_ticks.push_back(v);
  const std::vector<std::uint8_t> bytes = recording::encode_chunk(chunk, header_.nq);
  if (const std::string e = write_all(fd_, bytes); !e.empty()) {
    fail(fmt::format("recording stopped: writing chunk {} failed: {}", status().chunks + 1, e));
    return false;
  }
  {
    const std::lock_guard<std::mutex> lock(status_mutex_);
    status_.ticks += chunk.ticks.size();
    status_.chunks += 1;
    status_.bytes += bytes.size();
    status_.vmc_frames += chunk.vmc_ticks.size();
  }
  chunk.ticks.clear();
  chunk.vmc_ticks.clear();
  return true;
}

}  // namespace tonus::daemon
