// tonusd --record and --replay as the user runs them: the replay's VMC bytes,
// captured off the socket by the test, are the recorded run's, datagram for
// datagram; a daemon killed while recording leaves a file that replays up to
// its last second; truncated, corrupt and foreign files get clear answers.
#include <doctest/doctest.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "process.hpp"
#include "support/scratch_dir.hpp"
#include "vmc_capture.hpp"

using tonus::test::Process;
using tonus::test::VmcCapture;

namespace {

std::string temp(const std::string& name) { return tonus::test::scratch_path("tonusd-rec-" + name); }

struct Run {
  int rc = -1;
  std::string log;
  nlohmann::json summary = nlohmann::json::object();
};

Run tonusd(std::vector<std::string> args, const std::string& name) {
  const std::string json = temp(name + ".json");
  ::unlink(json.c_str());
  args.insert(args.end(), {"--json", json, "--no-control", "--no-viewer", "--no-realtime"});
  Process p(TONUSD, args, temp(name + ".log"));
  REQUIRE(p.started());
  Run r;
  r.rc = p.wait(std::chrono::seconds(90));
  r.log = p.output();
  if (std::ifstream in(json); in) r.summary = nlohmann::json::parse(in, nullptr, false);
  return r;
}

std::vector<unsigned char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const std::vector<unsigned char>& b, std::size_t n) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(n));
}

// One recorded demo run, shared by the tests below (made once).
struct Recorded {
  std::string path = temp("demo.tonusrec");
  Run run;
  std::vector<std::vector<unsigned char>> wire;
};

const Recorded& recorded() {
  static const Recorded r = [] {
    Recorded rec;
    VmcCapture cap;
    rec.run =
        tonusd({"--demo", "--seconds", "3", "--record", rec.path, "--vmc-port", std::to_string(cap.port())}, "record");
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the last datagrams in
    rec.wire = cap.raw();
    return rec;
  }();
  return r;
}

}  // namespace

TEST_CASE("tonusd --replay: the recorded run's VMC bytes again, datagram for datagram, faster than real time") {
  const Recorded& rec = recorded();
  INFO(rec.run.log);
  REQUIRE(rec.run.rc == 0);
  REQUIRE(rec.run.summary.contains("recording"));
  CHECK(rec.run.summary["recording"]["error"] == "");
  CHECK(rec.run.summary["recording"]["chunks"].get<int>() >= 3);
  REQUIRE(rec.wire.size() > 100);

  VmcCapture cap;
  const auto t0 = std::chrono::steady_clock::now();
  const Run replay = tonusd({"--replay", rec.path, "--speed", "3", "--vmc-port", std::to_string(cap.port())}, "replay");
  const double replay_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  INFO(replay.log);
  REQUIRE(replay.rc == 0);
  CHECK(replay.summary["replay"]["end"] == "finished");
  CHECK(replay.summary["ticks"] == rec.run.summary["ticks"]);
  CHECK(replay.summary["output_hash"] == rec.run.summary["output_hash"]);
  CHECK(replay.summary["vmc_hash"] == rec.run.summary["vmc_hash"]);
  // The check that is not tonusd's own: the bytes on the wire, compared by the test.
  const std::vector<std::vector<unsigned char>> wire = cap.raw();
  CHECK(wire.size() == rec.wire.size());
  std::size_t same = 0;
  for (std::size_t i = 0; i < std::min(wire.size(), rec.wire.size()); ++i) same += wire[i] == rec.wire[i] ? 1U : 0U;
  CHECK(same == rec.wire.size());
  // The gifts the recorded run reported, reported again.
  CHECK(replay.summary["gifts"] == rec.run.summary["gifts"]);
  MESSAGE("recorded " << rec.run.summary["ticks"] << " ticks, " << rec.wire.size() << " datagrams; replayed at x3 in "
                      << replay_s << " s");
  CHECK(replay_s < 3.0);  // the recorded run took 3 s of physics
}

TEST_CASE("tonusd --record: a daemon killed mid-take leaves a file that replays all but its last second") {
  const std::string path = temp("killed.tonusrec");
  Process p(TONUSD,
            {"--demo", "--seconds", "30", "--record", path, "--no-control", "--no-viewer", "--no-realtime",
             "--vmc-port", "9"},
            temp("killed.log"));
  REQUIRE(p.started());
  // The first chunk lands about a second into the take: from there, 2.5 s more, then SIGKILL.
  const auto past_header = [](const std::vector<unsigned char>& b) {  // "TONUSREC", version, length, JSON, CRC
    if (b.size() < 16) return false;
    std::size_t json = 0;
    for (std::size_t i = 0; i < 4; ++i) json |= static_cast<std::size_t>(b[12 + i]) << (8U * i);
    return b.size() > 16 + json + 4;
  };
  bool first_chunk = false;
  for (int i = 0; i < 1000 && !first_chunk; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    first_chunk = past_header(file_bytes(path));
  }
  REQUIRE(first_chunk);
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  p.kill(SIGKILL);
  const Run replay = tonusd({"--replay", path, "--speed", "0", "--vmc-port", "9"}, "killed-replay");
  INFO(replay.log);
  CHECK(replay.rc == 0);
  const std::string end = replay.summary["replay"]["end"].get<std::string>();
  CHECK((end == "finished" || end == "truncated"));
  const auto ticks = replay.summary["ticks"].get<std::uint64_t>();
  MESSAGE("killed about 3.5 s into the take: " << ticks << " ticks replayed (" << end << ")");
  CHECK(ticks >= 2300);  // at most about a second lost (a chunk a second, written within 0.1 s)
}

TEST_CASE("tonusd --replay: a truncated file replays to its last whole chunk, a corrupt or foreign one is refused") {
  const Recorded& rec = recorded();
  REQUIRE(rec.run.rc == 0);
  const std::vector<unsigned char> bytes = file_bytes(rec.path);
  REQUIRE(bytes.size() > 1000);

  const std::string cut = temp("cut.tonusrec");
  write_bytes(cut, bytes, bytes.size() * 6 / 10);
  const Run truncated = tonusd({"--replay", cut, "--speed", "0", "--vmc-port", "9"}, "cut");
  INFO(truncated.log);
  CHECK(truncated.rc == 0);
  CHECK(truncated.summary["replay"]["end"] == "truncated");
  CHECK(truncated.summary["ticks"].get<std::uint64_t>() > 0);
  CHECK(truncated.summary["ticks"].get<std::uint64_t>() < rec.run.summary["ticks"].get<std::uint64_t>());
  CHECK(truncated.log.find("ends inside a chunk") != std::string::npos);

  std::vector<unsigned char> bad = bytes;
  for (std::size_t i = bytes.size() / 2; i < bytes.size() / 2 + 8; ++i) bad[i] ^= 0xFF;
  const std::string corrupt = temp("corrupt.tonusrec");
  write_bytes(corrupt, bad, bad.size());
  const Run broken = tonusd({"--replay", corrupt, "--speed", "0", "--vmc-port", "9"}, "corrupt");
  INFO(broken.log);
  CHECK(broken.rc == 1);
  CHECK(broken.log.find("corrupt") != std::string::npos);
  CHECK(broken.summary["replay"]["end"] == "corrupt");

  const std::string foreign = temp("foreign.tonusrec");
  write_bytes(foreign, std::vector<unsigned char>(5000, 'x'), 5000);
  const Run refused = tonusd({"--replay", foreign}, "foreign");
  CHECK(refused.rc == 2);
  CHECK(refused.log.find("not a tonus recording") != std::string::npos);
  const Run missing = tonusd({"--replay", temp("nowhere.tonusrec")}, "missing");
  CHECK(missing.rc == 2);
  CHECK(missing.log.find("No such file") != std::string::npos);
}
