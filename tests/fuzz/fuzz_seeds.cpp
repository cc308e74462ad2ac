// Writes a seed corpus of valid encodings for every fuzz target, so short
// fuzz runs start from deep inside the decoders instead of from nothing.
// Usage: fuzz_seeds OUT_DIR  (creates OUT_DIR/<target>/seed-N files)
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tonus/protocol/can.hpp"
#include "tonus/protocol/candump.hpp"
#include "tonus/protocol/command.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/payloads.hpp"
#include "tonus/protocol/stream.hpp"

using namespace tonus::proto;
namespace fs = std::filesystem;

namespace {

void write(const fs::path& dir, int& counter, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(dir / ("seed-" + std::to_string(counter++)), std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

StreamMessage stream_message(std::uint8_t groups, std::uint8_t channels) {
  StreamMessage m{};
  m.group_count = groups;
  m.channel_count = channels;
  m.sequence = 0xFFFE;
  m.device_time_us = 0xFFFFFF00U;
  m.status = status_bit::calibrated | status_bit::block_lost;
  m.electrode_off = 1;
  for (std::size_t g = 0; g < groups; ++g) m.levels[g] = static_cast<std::uint16_t>(9000 * (g + 1));
  for (std::size_t c = 0; c < channels; ++c) m.envelopes[c] = static_cast<std::uint16_t>(1000 * (c + 1));
  return m;
}

std::vector<Request> requests() {
  std::vector<Request> out;
  Request r{};
  (void)make_request(Opcode::time_sync, 1, TimeSyncRequest{123456789}, r);
  out.push_back(r);
  (void)make_request(Opcode::set_config, 2, DeviceConfig{}, r);
  out.push_back(r);
  (void)make_request(Opcode::calibration_start, 3, CalibrationStart{}, r);
  out.push_back(r);
  (void)make_request(Opcode::reset, 4, ResetRequest{ResetKind::factory_defaults}, r);
  out.push_back(r);
  out.push_back(make_request(Opcode::get_device_info, 5));
  return out;
}

std::vector<Response> responses() {
  std::vector<Response> out;
  Response r{};
  const Request q = make_request(Opcode::get_device_info, 9);
  (void)make_response(q, Status::ok, DeviceInfo{}, r);
  out.push_back(r);
  (void)make_response(q, Status::ok, TimeSyncResponse{1, 2, 3}, r);
  out.push_back(r);
  (void)make_response(q, Status::ok, DeviceStats{}, r);
  out.push_back(r);
  (void)make_response(q, Status::ok, CalibrationStatus{}, r);
  out.push_back(r);
  (void)make_response(q, Status::ok, DeviceConfig{}, r);
  out.push_back(r);
  (void)make_response(q, Status::bad_value, SetConfigResult{ConfigField::lowpass_dhz}, r);
  out.push_back(r);
  return out;
}

template <class Message, class Encode>
std::vector<std::uint8_t> bytes_of(const Message& m, Encode encode) {
  std::array<std::uint8_t, kMaxMessageSize> buf{};
  std::size_t n = 0;
  (void)encode(m, buf, n);
  return {buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)};
}

// Frames in the layout fuzz_can.cpp reads: id u16, dlc, flags, 8 data bytes.
void append_frame(std::vector<std::uint8_t>& out, const CanFrame& f) {
  out.push_back(static_cast<std::uint8_t>(f.id));
  out.push_back(static_cast<std::uint8_t>(f.id >> 8U));
  out.push_back(f.dlc);
  out.push_back(f.flags);
  out.insert(out.end(), f.data.begin(), f.data.end());
}

// Small BVH texts in the layouts real exporters write: CMU-like (CRLF, a
// 6-channel root, ZYX joints, ".0083333"), Bandai-like (tabs, six channels
// on every joint, a tab after "Frames:"), and names with blanks, several End
// Sites, a joint without channels and interleaved channels.
constexpr const char* kBvhSeeds[] = {
    "HIERARCHY\r\nROOT Hips\r\n{\r\n\tOFFSET 0.00000 0.00000 0.00000\r\n"
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation \r\n"
    "\tJOINT LeftUpLeg\r\n\t{\r\n\t\tOFFSET 1.65674 -1.80282 0.62477\r\n"
    "\t\tCHANNELS 3 Zrotation Yrotation Xrotation\r\n\t\tEnd Site\r\n\t\t{\r\n"
    "\t\t\tOFFSET 0.00000 -0.00000 1.11249\r\n\t\t}\r\n\t}\r\n}\r\nMOTION\r\nFrames: 2\n"
    "Frame Time: .0083333\n10.4194 16.7048 -30.1003 0 0 0 0 -21 0\r\n"
    "10.5 16.7 -30.1 -1.5 2.25 3 4 5 -6.0000\r\n",
    "HIERARCHY\nROOT joint_Root\n{\n\tOFFSET 0.0 0.0 0.0\n"
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation \n\tJOINT Hips\n\t{\n"
    "\t\tOFFSET -0.726466 93.3139 -2.00062\n\t\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
    "Yrotation \n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0.0 0.0 0.0\n\t\t}\n\t}\n}\nMOTION\nFrames:\t1\n"
    "Frame Time:\t0.0333333\n0.000000 0.000000 0.000000 0.000000 0.000000 -0.000000 0.467354 92.389100 "
    "450.294000 -80.778900 -7.404020 160.050000 \n",
    "HIERARCHY\nROOT Bip01\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n"
    " JOINT Bip01 L Thigh {\n  OFFSET 1 0 0\n  CHANNELS 0\n  End Site\n  {\n   OFFSET 0 -1 0\n  }\n"
    "  End site {\n   OFFSET 0 -2 7.7e-06\n  }\n }\n JOINT Leaf\n {\n  OFFSET 0 1 0\n"
    "  CHANNELS 4 Yrotation Xposition Zrotation Xrotation\n }\n}\nMOTION\nFrames: 3\nFrame Time: 0.01\n"
    "1 2 3 45 +1 1e1 -2.5\n\n1 2 3 45 1 1E-3 .5\n-1 -2 -3 -45 -1 -1 -.5",
};

// OSC, written by hand (the seeds need no liblo): strings NUL-terminated and
// padded to 4 bytes, big-endian int32 and float32 arguments.
void osc_pad_string(std::vector<std::uint8_t>& out, const std::string& s) {
  out.insert(out.end(), s.begin(), s.end());
  do out.push_back(0);
  while (out.size() % 4 != 0);
}

void osc_be32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<std::uint8_t>(v >> static_cast<unsigned>(shift)));
}

std::vector<std::uint8_t> osc_message(const std::string& address, const std::string& name,
                                      const std::vector<float>& floats) {
  std::vector<std::uint8_t> m;
  osc_pad_string(m, address);
  osc_pad_string(m, "," + std::string(name.empty() ? "" : "s") + std::string(floats.size(), 'f'));
  if (!name.empty()) osc_pad_string(m, name);
  for (const float f : floats) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &f, sizeof bits);
    osc_be32(m, bits);
  }
  return m;
}

std::vector<std::uint8_t> osc_bundle(const std::vector<std::vector<std::uint8_t>>& elements) {
  std::vector<std::uint8_t> b;
  osc_pad_string(b, "#bundle");
  osc_be32(b, 0);
  osc_be32(b, 1);  // "immediately"
  for (const auto& e : elements) {
    osc_be32(b, static_cast<std::uint32_t>(e.size()));
    b.insert(b.end(), e.begin(), e.end());
  }
  return b;
}

// A VMC performer frame (every humanoid bone the retargeting needs) and a
// tracker frame (a headset, two controllers, three trackers), in Unity's frame.
std::vector<std::vector<std::uint8_t>> vmc_seeds() {
  const std::vector<float> pose{0.0F, 0.9F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F};
  std::vector<std::uint8_t> ok;  // /VMC/Ext/OK 1: a model is loaded
  osc_pad_string(ok, "/VMC/Ext/OK");
  osc_pad_string(ok, ",i");
  osc_be32(ok, 1);
  std::vector<std::vector<std::uint8_t>> performer{ok};
  performer.push_back(osc_message("/VMC/Ext/T", "", {12.5F}));
  performer.push_back(osc_message("/VMC/Ext/Root/Pos", "root", pose));
  for (const char* bone :
       {"Hips",          "Spine",         "Chest",        "UpperChest",   "Neck",          "Head",
        "LeftShoulder",  "LeftUpperArm",  "LeftLowerArm", "LeftHand",     "RightShoulder", "RightUpperArm",
        "RightLowerArm", "RightHand",     "LeftUpperLeg", "LeftLowerLeg", "LeftFoot",      "LeftToes",
        "RightUpperLeg", "RightLowerLeg", "RightFoot",    "RightToes"}) {
    performer.push_back(osc_message("/VMC/Ext/Bone/Pos", bone, {0.1F, 0.2F, 0.0F, 0.0F, 0.0F, 0.0F, 1.0F}));
  }
  std::vector<std::vector<std::uint8_t>> trackers{
      osc_message("/VMC/Ext/Hmd/Pos", "HMD-1", {0, 1.6F, 0, 0, 0, 0, 1}),
      osc_message("/VMC/Ext/Con/Pos", "LHR-L", {-0.3F, 1.2F, 0.2F, 0, 0, 0, 1}),
      osc_message("/VMC/Ext/Con/Pos", "LHR-R", {0.3F, 1.2F, 0.2F, 0, 0, 0, 1}),
      osc_message("/VMC/Ext/Tra/Pos", "T-waist", {0, 1.0F, 0, 0, 0, 0, 1}),
      osc_message("/VMC/Ext/Tra/Pos", "T-lfoot", {-0.1F, 0.1F, 0, 0, 0, 0, 1}),
      osc_message("/VMC/Ext/Tra/Pos", "T-rfoot", {0.1F, 0.1F, 0, 0, 0, 0, 1})};
  return {osc_bundle(performer), osc_bundle(trackers), osc_message("/VMC/Ext/Root/Pos", "root", pose),
          osc_bundle({osc_bundle(trackers), osc_message("/VMC/Ext/T", "", {13.0F})})};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  const fs::path root(argv[1]);
  for (const char* t : {"stream", "command", "hid_descriptor", "can", "candump", "bvh", "device", "usb_control", "vmc"})
    fs::create_directories(root / t);
  int n = 0;

  for (auto [g, c] : {std::pair<std::uint8_t, std::uint8_t>{4, 8}, {1, 1}, {6, 16}, {5, 13}}) {
    const StreamMessage m = stream_message(g, c);
    write(root / "stream", n, bytes_of(m, encode_stream));
    hid::Report report{};
    (void)hid::pack_stream(m, report);
    write(root / "stream", n, {report.begin(), report.end()});
  }
  for (const Request& r : requests()) write(root / "command", n, bytes_of(r, encode_request));
  for (const Response& r : responses()) write(root / "command", n, bytes_of(r, encode_response));
  write(root / "hid_descriptor", n, {hid::kReportDescriptor.begin(), hid::kReportDescriptor.end()});

  constexpr std::uint8_t kNode = 1;
  std::vector<std::uint8_t> frames{kNode};
  std::array<CanFrame, can::kMaxStreamFrames> cycle{};
  std::size_t count = 0;
  (void)can::encode_stream(stream_message(6, 16), kNode, true, cycle, count);
  for (std::size_t i = 0; i < count; ++i) append_frame(frames, cycle[i]);
  const auto req = bytes_of(requests()[1], encode_request);
  std::array<CanFrame, can::kMaxSegments> segs{};
  (void)can::segment(req, can::Function::request, kNode, segs, count);
  for (std::size_t i = 0; i < count; ++i) append_frame(frames, segs[i]);
  append_frame(frames, can::encode_heartbeat(can::Heartbeat{}, kNode));
  write(root / "can", n, frames);

  // fuzz_device: [kind][length][bytes] chunks. Every request as a HID output
  // report and as CAN segments to node 1, with sample blocks between them.
  std::vector<std::uint8_t> device;
  for (const Request& r : requests()) {
    hid::Report report{};
    (void)hid::pack_request(r, report);
    device.push_back(0);
    device.push_back(static_cast<std::uint8_t>(report.size()));
    device.insert(device.end(), report.begin(), report.end());
    device.insert(device.end(), {2, 16});
    device.insert(device.end(), 16, 0x80);
    std::array<CanFrame, can::kMaxSegments> parts{};
    (void)can::segment(bytes_of(r, encode_request), can::Function::request, kNode, parts, count);
    for (std::size_t i = 0; i < count; ++i) {
      device.push_back(1);
      device.push_back(static_cast<std::uint8_t>(2 + parts[i].dlc));
      device.push_back(static_cast<std::uint8_t>(parts[i].id));
      device.push_back(static_cast<std::uint8_t>(parts[i].id >> 8U));
      device.insert(device.end(), parts[i].data.begin(), parts[i].data.begin() + parts[i].dlc);
    }
  }
  write(root / "device", n, device);

  // fuzz_usb_control: a Linux-like enumeration, a SET_REPORT with its data
  // stage, an EP1 OUT request, a halt and a suspend.
  const std::vector<std::array<std::uint8_t, 8>> setups{
      {0x80, 6, 0x00, 0x01, 0, 0, 64, 0},  {0x00, 5, 7, 0, 0, 0, 0, 0},
      {0x80, 6, 0x00, 0x02, 0, 0, 255, 0}, {0x80, 6, 0x03, 0x03, 0x09, 0x04, 255, 0},
      {0x00, 9, 1, 0, 0, 0, 0, 0},         {0x21, 10, 0, 0, 0, 0, 0, 0},
      {0x81, 6, 0x00, 0x22, 0, 0, 255, 0}, {0xA1, 1, 0x01, 0x01, 0, 0, 64, 0},
      {0x02, 3, 0, 0, 0x81, 0, 0, 0},      {0x82, 0, 0, 0, 0x81, 0, 2, 0},
      {0x02, 1, 0, 0, 0x81, 0, 0, 0},      {0x21, 9, 0x02, 0x02, 0, 0, 64, 0}};
  std::vector<std::uint8_t> usb;
  for (const auto& st : setups) {
    usb.push_back(0);
    usb.insert(usb.end(), st.begin(), st.end());
  }
  hid::Report out_report{};
  (void)hid::pack_request(requests()[0], out_report);
  usb.push_back(1);
  usb.push_back(64);
  usb.insert(usb.end(), out_report.begin(), out_report.end());
  usb.push_back(2);
  usb.push_back(64);
  usb.insert(usb.end(), out_report.begin(), out_report.end());
  usb.insert(usb.end(), {4, 5});
  hid::Report in_report{};
  (void)hid::pack_stream(stream_message(4, 8), in_report);
  usb.insert(usb.end(), in_report.begin(), in_report.end());
  usb.push_back(3);
  write(root / "usb_control", n, usb);

  for (std::size_t i = 0; i < cycle.size(); ++i) {
    candump::Record rec{};
    rec.time_us = 1700000000000000ULL + i;
    (void)candump::set_iface(rec, "can0");
    rec.frame = cycle[i];
    std::array<char, candump::kMaxLine> line{};
    std::size_t len = 0;
    if (candump::format(rec, line, len) == Error::ok) write(root / "candump", n, {line.begin(), line.begin() + len});
  }
  for (const char* bvh : kBvhSeeds) {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(bvh);
    write(root / "bvh", n, {bytes, bytes + std::strlen(bvh)});
  }
  for (const std::vector<std::uint8_t>& datagram : vmc_seeds()) write(root / "vmc", n, datagram);
  std::printf("fuzz_seeds: wrote %d seeds under %s\n", n, root.c_str());
  return 0;
}
