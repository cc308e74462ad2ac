#include "tonus/host/vmc/sender.hpp"

#include <lo/lo.h>

#include <algorithm>
#include <cmath>
#include <string_view>
#include <vector>

#include "tonus/sim/human_bones.hpp"

namespace tonus::vmc {

namespace {

// liblo's LO_TT_IMMEDIATE is a C compound literal, which clang flags in C++.
constexpr lo_timetag kImmediate{0U, 1U};

std::uint64_t fnv1a(std::uint64_t h, const unsigned char* p, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ULL;
  }
  return h;
}

// The OSC messages of one frame, in order. Each message is owned here until
// a bundle takes it (a new message has no reference; lo_bundle_add_message
// adds the one lo_bundle_free_recursive drops, freeing it).
class Frame {
 public:
  Frame() { items_.reserve(sim::kBoneCount + 16); }
  ~Frame() {
    for (Item& it : items_) {
      if (it.msg != nullptr) lo_message_free(it.msg);
    }
  }
  Frame(const Frame&) = delete;
  Frame& operator=(const Frame&) = delete;

  lo_message add(const char* path) {
    items_.push_back({path, lo_message_new()});
    return items_.back().msg;
  }

  struct Item {
    const char* path;
    lo_message msg;
  };
  std::vector<Item>& items() { return items_; }

 private:
  std::vector<Item> items_;
};

void add_transform(lo_message m, const UnityTransform& t) {
  lo_message_add_float(m, static_cast<float>(t.pos_m.x()));
  lo_message_add_float(m, static_cast<float>(t.pos_m.y()));
  lo_message_add_float(m, static_cast<float>(t.pos_m.z()));
  const sim::Quat q = t.rot.normalized();
  lo_message_add_float(m, static_cast<float>(q.x()));
  lo_message_add_float(m, static_cast<float>(q.y()));
  lo_message_add_float(m, static_cast<float>(q.z()));
  lo_message_add_float(m, static_cast<float>(q.w()));
}

bool finite(const UnityTransform& t) {
  return sim::all_finite(t.pos_m) && t.rot.coeffs().allFinite() && t.rot.norm() > 1e-9;
}

bool finite(const VmcPose& p, std::span<const VmcObject> objects) {
  if (!finite(p.root)) return false;
  for (const UnityTransform& b : p.bone) {
    if (!finite(b)) return false;
  }
  for (const VmcObject& o : objects) {
    if (!finite(o.pose) || !std::isfinite(o.size_m)) return false;
  }
  return true;
}

void build_frame(Frame& f, const VmcPose& pose, double time_s, std::span<const VmcObject> objects,
                 const std::array<float, 4>* stiffness) {
  // V2.5 / V2.7 fields: loaded, calibration state 3 (calibrated), calibration mode 0 (normal), tracking ok.
  lo_message_add(f.add("/VMC/Ext/OK"), "iiii", 1, 3, 0, 1);
  lo_message_add_float(f.add("/VMC/Ext/T"), static_cast<float>(std::isfinite(time_s) ? time_s : 0.0));
  lo_message root = f.add("/VMC/Ext/Root/Pos");
  lo_message_add_string(root, "root");
  add_transform(root, pose.root);
  for (const sim::BoneInfo& b : sim::kBones) {
    lo_message m = f.add("/VMC/Ext/Bone/Pos");
    // HumanBodyBones names are string literals: NUL-terminated.
    lo_message_add_string(m, b.name.data());
    add_transform(m, pose.bone[sim::index(b.bone)]);
  }
  if (objects.empty()) f.add("/tonus/Object/Clear");
  for (const VmcObject& o : objects) {
    lo_message m = f.add("/tonus/Object/Pos");
    lo_message_add_int32(m, o.id);
    lo_message_add_string(m, to_string(o.kind));
    lo_message_add_float(m, static_cast<float>(o.size_m));
    add_transform(m, o.pose);
  }
  if (stiffness != nullptr &&
      std::all_of(stiffness->begin(), stiffness->end(), [](float v) { return !std::isnan(v); })) {
    lo_message m = f.add("/tonus/Stiffness");
    for (const float v : *stiffness) lo_message_add_float(m, std::clamp(v, 0.0F, 1.0F));
  }
}

constexpr std::size_t kBundleHeaderBytes = 16;  // "#bundle\0" + time tag
constexpr std::size_t kElementSizeBytes = 4;    // each element's int32 size

}  // namespace

VmcSender::VmcSender(const SenderOptions& options) : options_(options) {
  if (options_.port < 1 || options_.port > 65535) {
    error_ = "VMC send port must be 1 to 65535, got " + std::to_string(options_.port);
    return;
  }
  if (options_.max_datagram_bytes < kMinDatagramBytes || options_.max_datagram_bytes > kMaxDatagramBytes) {
    error_ = "VMC max datagram size must be " + std::to_string(kMinDatagramBytes) + " to " +
             std::to_string(kMaxDatagramBytes) + " bytes, got " + std::to_string(options_.max_datagram_bytes);
    return;
  }
  if (options_.host.empty()) {
    error_ = "VMC send host is empty";
    return;
  }
  scratch_.resize(options_.max_datagram_bytes);
  address_ = lo_address_new(options_.host.c_str(), std::to_string(options_.port).c_str());
  if (address_ == nullptr) error_ = "VMC sender: liblo refused the address " + options_.host;
}

VmcSender::~VmcSender() {
  if (address_ != nullptr) lo_address_free(static_cast<lo_address>(address_));
}

bool VmcSender::send(const VmcPose& pose, double time_s, std::span<const VmcObject> objects,
                     const std::array<float, 4>* stiffness) {
  if (address_ == nullptr) return false;
  if (!finite(pose, objects)) {
    ++counters_.rejected;
    return false;
  }
  const auto addr = static_cast<lo_address>(address_);
  Frame frame;
  build_frame(frame, pose, time_s, objects, stiffness);
  std::vector<Frame::Item>& items = frame.items();

  bool all_sent = true;
  const auto note_error = [&] {
    ++counters_.send_errors;
    all_sent = false;
    const char* why = lo_address_errstr(addr);
    last_send_error_ = std::string("VMC send to ") + options_.host + ":" + std::to_string(options_.port) +
                       " failed: " + (why != nullptr ? why : "unknown error");
  };

  if (!options_.bundle) {
    for (Frame::Item& it : items) {
      std::size_t size = lo_message_length(it.msg, it.path);
      scratch_.resize(std::max(scratch_.size(), size));
      if (lo_message_serialise(it.msg, it.path, scratch_.data(), &size) != nullptr) {
        counters_.wire_hash = fnv1a(counters_.wire_hash, scratch_.data(), size);
      }
      if (lo_send_message(addr, it.path, it.msg) < 0) {
        note_error();
        continue;
      }
      ++counters_.messages;
      counters_.bytes += lo_message_length(it.msg, it.path);
    }
  } else {
    // Greedy packing in order: a message goes into the current bundle if the
    // bundle stays within the limit, else the bundle is sent and a new one
    // started. A single message always fits (kMinDatagramBytes).
    std::size_t i = 0;
    while (i < items.size()) {
      lo_bundle b = lo_bundle_new(kImmediate);
      std::size_t length = kBundleHeaderBytes;
      std::size_t count = 0;
      for (; i < items.size(); ++i) {
        const std::size_t element = kElementSizeBytes + lo_message_length(items[i].msg, items[i].path);
        if (count > 0 && length + element > options_.max_datagram_bytes) break;
        lo_bundle_add_message(b, items[i].path, items[i].msg);
        items[i].msg = nullptr;  // the bundle's now: lo_bundle_free_recursive frees it
        length += element;
        ++count;
      }
      std::size_t serialised = lo_bundle_length(b);
      scratch_.resize(std::max(scratch_.size(), serialised));
      if (lo_bundle_serialise(b, scratch_.data(), &serialised) != nullptr) {
        counters_.wire_hash = fnv1a(counters_.wire_hash, scratch_.data(), serialised);
      }
      if (lo_send_bundle(addr, b) < 0) {
        note_error();
      } else {
        ++counters_.bundles;
        counters_.messages += count;
        counters_.bytes += serialised;
      }
      lo_bundle_free_recursive(b);
    }
  }
  if (all_sent) ++counters_.frames;
  return all_sent;
}

}  // namespace tonus::vmc
