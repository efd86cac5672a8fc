#pragma once
// The conversation between the simulation (`airtwin view`) and its window process
// (`airtwin-viewer`) over one Unix stream socket: typed, length-prefixed messages.
//
//   window -> simulation: kReady (the window is open) or kError (text: why not), then kNext
//                         (simulate the next camera frame) or kQuit (the window was closed)
//   simulation -> window: kModel (MJB bytes), then kFrame (viewer/view_frame.h) after each
//                         kNext, and kEnd (text: the run's verdict) when the run is over
//
// The window paces the run: the simulation waits for kNext after every frame, so pausing the
// window pauses the run, and the window asks for frames as fast as its speed setting wants.
// Writes never raise SIGPIPE (MSG_NOSIGNAL): a peer that went away is an error, not a signal.

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace airtwin {

enum class ViewMessageType : uint8_t {
  kReady = 1,
  kError = 2,
  kModel = 3,
  kFrame = 4,
  kEnd = 5,
  kNext = 6,
  kQuit = 7,
};

struct ViewMessage {
  ViewMessageType type = ViewMessageType::kReady;
  std::string payload;
};

/// The other process went away, broke the protocol, or the socket failed.
class ViewerError : public std::runtime_error {
 public:
  explicit ViewerError(const std::string& message) : std::runtime_error(message) {}
};

/// Sends one message on socket `fd`. Throws ViewerError when the peer is gone.
void send_view_message(int fd, ViewMessageType type, std::string_view payload = {});

/// Waits for the next message on `fd`; nullopt when the peer closed the socket between
/// messages. Throws ViewerError on a truncated message, an unknown type or a socket error.
std::optional<ViewMessage> receive_view_message(int fd);

}  // namespace airtwin
