#include <doctest/doctest.h>

#include <array>
#include <random>

#include "support/mutate.hpp"
#include "tonus/protocol/stream.hpp"

using namespace tonus::proto;

namespace {

StreamMessage random_message(std::mt19937& rng, std::uint8_t groups, std::uint8_t channels) {
  std::uniform_int_distribution<unsigned> u16(0, 0xFFFF);
  StreamMessage m{};
  m.group_count = groups;
  m.channel_count = channels;
  m.sequence = static_cast<std::uint16_t>(u16(rng));
  m.device_time_us = static_cast<std::uint32_t>(u16(rng) << 16U | u16(rng));
  m.status = static_cast<std::uint16_t>(u16(rng));
  const auto mask = static_cast<std::uint16_t>((1U << channels) - 1U);
  m.electrode_off = static_cast<std::uint16_t>(u16(rng) & mask);
  m.saturation = static_cast<std::uint16_t>(u16(rng) & mask);
  m.artifact = static_cast<std::uint16_t>(u16(rng) & mask);
  for (std::size_t g = 0; g < groups; ++g) m.levels[g] = static_cast<std::uint16_t>(u16(rng));
  for (std::size_t c = 0; c < channels; ++c) m.envelopes[c] = static_cast<std::uint16_t>(u16(rng));
  return m;
}

}  // namespace

TEST_CASE("stream messages round-trip for every group and channel count") {
  std::mt19937 rng(42);
  for (std::uint8_t g = 1; g <= kMaxGroups; ++g) {
    for (std::uint8_t c = 1; c <= kMaxChannels; ++c) {
      const StreamMessage m = random_message(rng, g, c);
      std::array<std::uint8_t, kMaxMessageSize> buf{};
      std::size_t n = 0;
      REQUIRE(encode_stream(m, buf, n) == Error::ok);
      CHECK(n == stream_message_size(g, c));
      CHECK(n <= kMaxMessageSize);
      StreamMessage back{};
      REQUIRE(decode_stream(std::span(buf).first(n), back) == Error::ok);
      CHECK(back == m);
    }
  }
}

TEST_CASE("stream encoder refuses invalid messages and small buffers") {
  StreamMessage m{};
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 99;
  m.group_count = 0;
  CHECK(encode_stream(m, buf, n) == Error::bad_length);
  CHECK(n == 0);
  m.group_count = kMaxGroups + 1;
  CHECK(encode_stream(m, buf, n) == Error::bad_length);
  m.group_count = 4;
  m.channel_count = kMaxChannels + 1;
  CHECK(encode_stream(m, buf, n) == Error::bad_length);
  m.channel_count = 8;
  m.saturation = 1U << 8U;  // channel 8 does not exist
  CHECK(encode_stream(m, buf, n) == Error::bad_value);
  m.saturation = 0;
  std::array<std::uint8_t, 20> small{};
  CHECK(encode_stream(m, small, n) == Error::buffer_too_small);
}

TEST_CASE("stream decoder: every truncation is an error") {
  std::mt19937 rng(1);
  const StreamMessage m = random_message(rng, 4, 8);
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_stream(m, buf, n) == Error::ok);
  for (std::size_t len = 0; len < n; ++len) {
    StreamMessage out{};
    CHECK(decode_stream(std::span(buf).first(len), out) == Error::truncated);
  }
}

TEST_CASE("stream decoder: wrong version and bad counts are refused") {
  std::mt19937 rng(2);
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_stream(random_message(rng, 4, 8), buf, n) == Error::ok);
  StreamMessage out{};
  auto bad = buf;
  bad[0] = 2;
  CHECK(decode_stream(bad, out) == Error::bad_version);
  bad = buf;
  bad[1] = 7;
  CHECK(decode_stream(bad, out) == Error::bad_length);
  bad = buf;
  bad[2] = 0;
  CHECK(decode_stream(bad, out) == Error::bad_length);
}

TEST_CASE("stream decoder: every single-byte corruption is an error or a self-consistent message") {
  std::mt19937 rng(3);
  const StreamMessage m = random_message(rng, 4, 8);
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_stream(m, buf, n) == Error::ok);
  std::size_t errors = 0;
  std::size_t valid = 0;
  tonus::test::for_each_byte_corruption(std::span(buf).first(n), [&](std::span<const std::uint8_t> bytes) {
    StreamMessage out{};
    const Error e = decode_stream(bytes, out);
    if (e != Error::ok) {
      ++errors;
      return;
    }
    ++valid;
    // A message that decodes must re-encode to the same bytes (byte 3, once
    // reserved, is the boot epoch: every byte is a field now).
    std::array<std::uint8_t, kMaxMessageSize> again{};
    std::size_t m2 = 0;
    REQUIRE(encode_stream(out, again, m2) == Error::ok);
    REQUIRE(m2 <= bytes.size());
    for (std::size_t i = 0; i < m2; ++i) {
      CHECK(again[i] == bytes[i]);
    }
  });
  CHECK(errors > 0);
  CHECK(valid > 0);
}

TEST_CASE("boot epoch rides in byte 3, and a version-1.0 report (byte 3 = 0) decodes as unknown") {
  StreamMessage m{};
  m.boot_epoch = 0xA5;
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  REQUIRE(encode_stream(m, buf, n) == Error::ok);
  CHECK(buf[3] == 0xA5);
  StreamMessage back{};
  REQUIRE(decode_stream(std::span(buf).first(n), back) == Error::ok);
  CHECK(back.boot_epoch == 0xA5);
  CHECK(back == m);
  buf[3] = 0;
  REQUIRE(decode_stream(std::span(buf).first(n), back) == Error::ok);
  CHECK(back.boot_epoch == kBootEpochUnknown);
}
