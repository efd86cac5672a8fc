#include "viewer/viewer_channel.h"

#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace airtwin {
namespace {

// A message: 1 byte of type, 8 bytes of payload length (host order), the payload.
constexpr size_t kHeaderBytes = 9;
// Larger payloads are a broken peer, not a model or a frame (the 25-tracer model is ~1 MB).
constexpr uint64_t kMaxPayloadBytes = uint64_t{1} << 31;

void send_all(int fd, const char* data, size_t n) {
  while (n > 0) {
    const ssize_t sent = ::send(fd, data, n, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) {
      throw ViewerError(std::string("viewer connection lost while sending: ") +
                        std::strerror(errno));
    }
    data += sent;
    n -= static_cast<size_t>(sent);
  }
}

// Reads exactly n bytes; false when the peer closed before the first byte.
bool receive_all(int fd, char* data, size_t n, bool at_message_start) {
  size_t got = 0;
  while (got < n) {
    const ssize_t r = ::recv(fd, data + got, n - got, 0);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      throw ViewerError(std::string("viewer connection failed: ") + std::strerror(errno));
    }
    if (r == 0) {
      if (got == 0 && at_message_start) return false;
      throw ViewerError("viewer connection closed in the middle of a message");
    }
    got += static_cast<size_t>(r);
  }
  return true;
}

}  // namespace

void send_view_message(int fd, ViewMessageType type, std::string_view payload) {
  char header[kHeaderBytes];
  header[0] = static_cast<char>(type);
  const uint64_t n = payload.size();
  std::memcpy(header + 1, &n, sizeof(n));
  send_all(fd, header, kHeaderBytes);
  send_all(fd, payload.data(), payload.size());
}

std::optional<ViewMessage> receive_view_message(int fd) {
  char header[kHeaderBytes];
  if (!receive_all(fd, header, kHeaderBytes, true)) return std::nullopt;
  const auto type = static_cast<uint8_t>(header[0]);
  if (type < static_cast<uint8_t>(ViewMessageType::kReady) ||
      type > static_cast<uint8_t>(ViewMessageType::kQuit)) {
    throw ViewerError("viewer connection: unknown message type " + std::to_string(type));
  }
  uint64_t n = 0;
  std::memcpy(&n, header + 1, sizeof(n));
  if (n > kMaxPayloadBytes) {
    throw ViewerError("viewer connection: a message of " + std::to_string(n) + " bytes");
  }
  ViewMessage message;
  message.type = static_cast<ViewMessageType>(type);
  message.payload.resize(static_cast<size_t>(n));
  receive_all(fd, message.payload.data(), message.payload.size(), false);
  return message;
}

}  // namespace airtwin
