// One UDP datagram as OSC: a message, or a bundle of elements (messages or
// nested bundles), each checked before use. liblo's lo_message_deserialise
// checks a message (path, type tags, argument sizes); the bundle framing is
// walked here, so a bad element stops the walk without losing the elements
// before it, and a bundle's time tag never delays dispatch (liblo's server
// would queue a bundle stamped in the future by a sender's clock).
#pragma once

#include <lo/lo.h>

#include <cstddef>

namespace tonus::vmc::detail {

class OscSink {
 public:
  virtual void bundle_begin() = 0;
  virtual void bundle_end() = 0;
  // A decoded message; `msg` lives for the call only.
  virtual void message(const char* path, lo_message msg) = 0;
  // Something that is not valid OSC: a bad message, a truncated or
  // mis-framed bundle element, bundles nested too deep.
  virtual void malformed() = 0;

 protected:
  OscSink() = default;
  ~OscSink() = default;
  OscSink(const OscSink&) = default;
  OscSink& operator=(const OscSink&) = default;
};

inline constexpr int kMaxBundleDepth = 8;

// Decodes `data` (size bytes, 4-byte aligned) into the sink. Every
// bundle_begin is matched by a bundle_end, even when an element is bad.
void decode_datagram(unsigned char* data, std::size_t size, OscSink& sink);

}  // namespace tonus::vmc::detail
