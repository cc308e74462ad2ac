// The recording format and the record -> replay loop, in process: chunks
// round-trip bit for bit (NaN payloads included); a file cut at any byte
// reads up to its last whole chunk; any flipped byte is caught, never read
// as a different chunk; a core fed a recording's inputs reproduces the
// recorded core's outputs (hash after every chunk), and a tampered
// recording is reported as diverged.
#include <doctest/doctest.h>

#include <unistd.h>

#include <array>
#include <bit>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>

#include "daemon_fixtures.hpp"
#include "tonus/host/daemon/recorder.hpp"
#include "tonus/host/daemon/replay.hpp"

using namespace tonus;
using namespace tonus::daemon;

namespace {

std::string temp_path(const std::string& name) {
  return "/tmp/tonus-recording-test-" + std::to_string(::getpid()) + "-" + name;
}

std::vector<std::uint8_t> read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_all(const std::string& path, const std::vector<std::uint8_t>& bytes, std::size_t n) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(n));
}

// A chunk with everything a tick can carry, values drawn at random (and a NaN).
recording::Chunk random_chunk(std::mt19937_64& rng, int nq, std::uint64_t first_tick, std::size_t ticks) {
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  recording::Chunk c;
  c.first_tick = first_tick;
  c.pose_hash = rng();
  c.vmc_ticks = {first_tick + 3, first_tick + 3, first_tick + 20};
  std::int64_t t = 1'000'000'000;
  for (std::size_t k = 0; k < ticks; ++k) {
    recording::TickInputs in;
    t += (k % 7 == 0) ? 2000 : 1000;
    in.now_us = t;
    if (k % 2 == 0) {
      BandSample b;
      b.arrival_us = t - 300;
      b.sampled_host_us = k % 4 == 0 ? 0 : t - 2500;
      b.levels = {u(rng), u(rng), std::numeric_limits<double>::quiet_NaN(), -0.0};
      b.sequence = static_cast<std::uint16_t>(k);
      in.band.push_back(b);
    }
    if (k % 8 == 0) {
      PoseSample p;
      p.t_us = t - 100;
      p.cut = k == 16;
      for (int i = 0; i < nq; ++i) p.qpos[static_cast<std::size_t>(i)] = u(rng);
      in.poses.push_back(p);
    }
    if (k == 5) {
      Command g;
      g.kind = Command::Kind::gift;
      g.id = 42;
      g.gift = GiftKind::ball;
      g.ball.target = sim::Bone::Head;
      g.ball.direction = sim::Vec3(u(rng), u(rng), u(rng));
      g.cube.target = sim::Bone::LeftHand;
      g.cube.height_m = u(rng);
      in.commands.push_back(g);
      Command o;
      o.kind = Command::Kind::stiffness_override;
      o.levels = {0.1, 0.2, 0.3, 0.4};
      in.commands.push_back(o);
    }
    c.ticks.push_back(std::move(in));
  }
  return c;
}

// Bitwise equality, so NaN payloads and -0.0 count.
template <std::size_t N>
bool same_bits(const std::array<double, N>& a, const std::array<double, N>& b) {
  for (std::size_t i = 0; i < N; ++i) {
    if (std::bit_cast<std::uint64_t>(a[i]) != std::bit_cast<std::uint64_t>(b[i])) return false;
  }
  return true;
}

bool same_band(const BandSample& a, const BandSample& b) {
  return a.arrival_us == b.arrival_us && a.sampled_host_us == b.sampled_host_us && a.sequence == b.sequence &&
         same_bits(a.levels, b.levels);
}

bool same_command(const Command& a, const Command& b) {
  return a.kind == b.kind && a.id == b.id && a.gift == b.gift && a.ball.target == b.ball.target &&
         a.ball.direction == b.ball.direction && a.ball.mass_kg == b.ball.mass_kg &&
         a.ball.lifetime_s == b.ball.lifetime_s && a.cube.target == b.cube.target &&
         a.cube.height_m == b.cube.height_m && a.cube.edge_m == b.cube.edge_m && same_bits(a.levels, b.levels);
}

bool same_chunk(const recording::Chunk& a, const recording::Chunk& b) {
  if (a.first_tick != b.first_tick || a.pose_hash != b.pose_hash || a.vmc_ticks != b.vmc_ticks ||
      a.ticks.size() != b.ticks.size()) {
    return false;
  }
  for (std::size_t k = 0; k < a.ticks.size(); ++k) {
    const recording::TickInputs& x = a.ticks[k];
    const recording::TickInputs& y = b.ticks[k];
    if (x.now_us != y.now_us || x.band.size() != y.band.size() || x.poses.size() != y.poses.size() ||
        x.commands.size() != y.commands.size()) {
      return false;
    }
    for (std::size_t i = 0; i < x.band.size(); ++i) {
      if (!same_band(x.band[i], y.band[i])) return false;
    }
    for (std::size_t i = 0; i < x.poses.size(); ++i) {
      if (x.poses[i].t_us != y.poses[i].t_us || x.poses[i].cut != y.poses[i].cut ||
          !same_bits(x.poses[i].qpos, y.poses[i].qpos)) {
        return false;
      }
    }
    for (std::size_t i = 0; i < x.commands.size(); ++i) {
      if (!same_command(x.commands[i], y.commands[i])) return false;
    }
  }
  return true;
}

// A file of a header and `n` random chunks; returns the chunks and each chunk's end offset.
std::vector<recording::Chunk> write_recording(const std::string& path, int nq, int n, std::vector<std::size_t>& ends) {
  std::mt19937_64 rng(7);
  recording::Header h;
  h.config_toml = "[physics]\nrate_hz = 1000.0\n";
  h.nq = nq;
  std::vector<std::uint8_t> file = recording::encode_header(h);
  std::vector<recording::Chunk> chunks;
  for (int i = 0; i < n; ++i) {
    chunks.push_back(random_chunk(rng, nq, 1 + 40 * static_cast<std::uint64_t>(i), 40));
    const std::vector<std::uint8_t> b = recording::encode_chunk(chunks.back(), nq);
    file.insert(file.end(), b.begin(), b.end());
    ends.push_back(file.size());
  }
  write_all(path, file, file.size());
  return chunks;
}

}  // namespace

TEST_CASE("recording: chunks round-trip bit for bit, NaN payloads and signed zeros included") {
  const int nq = test::daemon_humanoid().nq;
  std::vector<std::size_t> ends;
  const std::string path = temp_path("roundtrip");
  const std::vector<recording::Chunk> chunks = write_recording(path, nq, 3, ends);
  std::string error;
  std::optional<recording::Reader> r = recording::Reader::open(path, error);
  REQUIRE_MESSAGE(r, error);
  CHECK(r->header().nq == nq);
  CHECK(r->header().config_toml == "[physics]\nrate_hz = 1000.0\n");
  recording::Chunk c;
  for (const recording::Chunk& expected : chunks) {
    REQUIRE(r->next(c) == recording::Reader::Status::chunk);
    CHECK(same_chunk(c, expected));
  }
  CHECK(r->next(c) == recording::Reader::Status::end);
  ::unlink(path.c_str());
}

TEST_CASE("recording: a file cut at any byte reads to its last whole chunk, then says truncated") {
  const int nq = test::daemon_humanoid().nq;
  std::vector<std::size_t> ends;
  const std::string path = temp_path("whole");
  const std::vector<recording::Chunk> chunks = write_recording(path, nq, 2, ends);
  const std::vector<std::uint8_t> bytes = read_all(path);
  const std::string cut = temp_path("cut");
  int checked = 0;
  for (std::size_t n = ends[0] - 40; n < bytes.size(); n += 3) {  // inside chunk 1's tail, and all of chunk 2
    write_all(cut, bytes, n);
    std::string error;
    std::optional<recording::Reader> r = recording::Reader::open(cut, error);
    REQUIRE(r);
    recording::Chunk c;
    std::size_t whole = 0;
    recording::Reader::Status s;
    while ((s = r->next(c)) == recording::Reader::Status::chunk) {
      CHECK(same_chunk(c, chunks[whole]));
      ++whole;
    }
    const std::size_t expected_whole = n >= ends[1] ? 2 : n >= ends[0] ? 1 : 0;
    CHECK(whole == expected_whole);
    CHECK(s == (n == ends[0] ? recording::Reader::Status::end : recording::Reader::Status::truncated));
    ++checked;
  }
  CHECK(checked > 100);
  ::unlink(path.c_str());
  ::unlink(cut.c_str());
}

TEST_CASE("recording: a flipped byte anywhere is caught (bad header or corrupt chunk), never read as other data") {
  const int nq = test::daemon_humanoid().nq;
  std::vector<std::size_t> ends;
  const std::string path = temp_path("flip-src");
  const std::vector<recording::Chunk> chunks = write_recording(path, nq, 2, ends);
  const std::vector<std::uint8_t> bytes = read_all(path);
  const std::string flipped = temp_path("flipped");
  int header_refused = 0, corrupt = 0, truncated = 0;
  for (std::size_t at = 0; at < bytes.size(); at += 5) {
    std::vector<std::uint8_t> b = bytes;
    b[at] ^= 0x5A;
    write_all(flipped, b, b.size());
    std::string error;
    std::optional<recording::Reader> r = recording::Reader::open(flipped, error);
    if (!r) {
      CHECK(!error.empty());
      ++header_refused;
      continue;
    }
    recording::Chunk c;
    std::size_t k = 0;
    recording::Reader::Status s;
    while ((s = r->next(c)) == recording::Reader::Status::chunk) {
      REQUIRE(k < chunks.size());
      CHECK(same_chunk(c, chunks[k]));  // whatever is read is what was written
      ++k;
    }
    CHECK(s != recording::Reader::Status::end);  // the flip never goes unnoticed
    if (s == recording::Reader::Status::corrupt) {
      CHECK(!r->error().empty());
      ++corrupt;
    } else {
      ++truncated;  // a length field grown past the end of the file
    }
  }
  MESSAGE(header_refused << " flips refused at the header, " << corrupt << " corrupt chunks, " << truncated
                         << " read as truncated");
  CHECK(header_refused > 0);
  CHECK(corrupt > 0);
  ::unlink(path.c_str());
  ::unlink(flipped.c_str());
}

TEST_CASE("recording: a core fed a recording's inputs reproduces its outputs, a tampered one is reported diverged") {
  const sim::Model& model = test::daemon_humanoid();
  std::string error;
  PhysicsCoreConfig cfg;
  auto live = PhysicsCore::create(model, cfg, error);
  REQUIRE(live);
  recording::Header h;
  h.nq = model.nq;
  h.rate_hz = 1000.0;
  const std::string path = temp_path("core");
  auto recorder = Recorder::create(path, h, error);
  REQUIRE_MESSAGE(recorder, error);
  live->set_recorder(recorder.get());
  recorder->start();
  // 2.5 s of a band, a swaying tracker and two gifts, ticked by hand.
  PoseSample pose;
  pose.qpos = model.qpos0;
  const std::int64_t t0 = 5'000'000;
  for (int k = 0; k < 2500; ++k) {
    const std::int64_t now = t0 + std::int64_t{1000} * k;
    BandSample b;
    b.arrival_us = now - 200;
    b.levels.fill(0.5 + 0.4 * std::sin(k * 0.003));
    live->push_band(b);
    if (k % 8 == 0) {
      pose.t_us = now;
      pose.qpos[1] = 0.1 * std::sin(k * 0.005);
      live->push_pose(pose);
    }
    if (k == 300 || k == 1200) {
      Command g;
      g.kind = Command::Kind::gift;
      g.id = static_cast<std::uint32_t>(k);
      g.gift = k == 300 ? GiftKind::cube : GiftKind::ball;
      live->push_command(g);
    }
    live->tick(now);
  }
  recorder->stop();
  const RecorderStatus rs = recorder->status();
  CHECK(rs.error.empty());
  CHECK(rs.ticks == 2500);
  CHECK(rs.chunks >= 3);

  auto replayed = PhysicsCore::create(model, cfg, error);
  REQUIRE(replayed);
  std::optional<recording::Reader> reader = recording::Reader::open(path, error);
  REQUIRE(reader);
  ReplayDriver driver(*replayed, nullptr, std::move(*reader), 0.0);
  driver.start();
  for (int i = 0; i < 1000 && !driver.done(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  REQUIRE(driver.done());
  driver.stop();
  const ReplayStatus st = driver.status();
  INFO(st.error);
  CHECK(st.end == ReplayEnd::finished);
  CHECK(st.ticks == 2500);
  CHECK(st.chunks == rs.chunks);
  CHECK(replayed->stats().output_hash == live->stats().output_hash);
  CHECK(replayed->stats().commands == 2);

  // The same recording with one band report changed (re-encoded with a valid
  // checksum): the replay runs, and says where its outputs part.
  reader = recording::Reader::open(path, error);
  REQUIRE(reader);
  std::vector<std::uint8_t> file = recording::encode_header(reader->header());
  recording::Chunk c;
  int n = 0;
  while (reader->next(c) == recording::Reader::Status::chunk) {
    if (n++ == 1) c.ticks[100].band.at(0).levels[0] += 0.25;
    const std::vector<std::uint8_t> b = recording::encode_chunk(c, model.nq);
    file.insert(file.end(), b.begin(), b.end());
  }
  const std::string tampered = temp_path("tampered");
  write_all(tampered, file, file.size());
  auto again = PhysicsCore::create(model, cfg, error);
  reader = recording::Reader::open(tampered, error);
  REQUIRE(reader);
  ReplayDriver second(*again, nullptr, std::move(*reader), 0.0);
  second.start();
  for (int i = 0; i < 1000 && !second.done(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  second.stop();
  CHECK(second.status().end == ReplayEnd::diverged);
  CHECK(second.status().chunks == 1);  // the first chunk still matched
  CHECK(second.status().error.find("chunk 2") != std::string::npos);
  ::unlink(path.c_str());
  ::unlink(tampered.c_str());
}
