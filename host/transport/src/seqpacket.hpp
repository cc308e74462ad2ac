// Shared helpers of the SOCK_SEQPACKET seams: connect by path, timed receive.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace tonus::host::detail {

// Connected socket fd, or -1 with `error` set.
int connect_seqpacket(const std::string& path, std::string& error);
// One datagram: its real size (may exceed out.size(): truncated), 0 timeout, -1 closed/error.
long receive_datagram(int fd, std::span<std::uint8_t> out, int timeout_ms, std::string& error);
bool send_datagram(int fd, std::span<const std::uint8_t> bytes, std::string& error);

}  // namespace tonus::host::detail
