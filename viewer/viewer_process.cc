#include "viewer/viewer_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

extern char** environ;

namespace airtwin {

ViewerProcess::ViewerProcess(const std::string& program, const std::vector<std::string>& args) {
  // The socket: our end closed on exec, the window's end inherited under its own number.
  int sv[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM, 0, sv) != 0) {
    throw ViewerError(std::string("cannot create the viewer's socket: ") + std::strerror(errno));
  }
  ::fcntl(sv[0], F_SETFD, FD_CLOEXEC);
  std::vector<std::string> argv_text = {program};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  argv_text.push_back("--fd");
  argv_text.push_back(std::to_string(sv[1]));
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const int spawned = ::posix_spawn(&pid_, program.c_str(), nullptr, nullptr, argv.data(), environ);
  ::close(sv[1]);
  fd_ = sv[0];
  if (spawned != 0) {
    ::close(fd_);
    throw ViewerError("cannot start the viewer window program " + program + ": " +
                      std::strerror(spawned));
  }
  // Wait for the window: open, or the reason it is not.
  std::optional<ViewMessage> first;
  try {
    first = receive_view_message(fd_);
  } catch (const ViewerError&) {
    first.reset();
  }
  if (first && first->type == ViewMessageType::kReady) return;
  std::string why = first && first->type == ViewMessageType::kError
                        ? first->payload
                        : "the viewer window program " + program + " ended before its window " +
                              "opened (" + exit_description(2.0) + ")";
  ::close(fd_);
  fd_ = -1;
  exit_description(2.0);
  throw ViewerError(why);
}

ViewerProcess::~ViewerProcess() {
  if (fd_ >= 0) ::close(fd_);
  if (pid_ > 0) exit_description(2.0);
}

std::string ViewerProcess::exit_description(double wait_s) {
  if (pid_ <= 0) return "ended";
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(std::max(wait_s, 0.0));
  int status = 0;
  for (;;) {
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) break;
    if (r < 0 && errno != EINTR) return "ended";
    if (std::chrono::steady_clock::now() >= deadline) {
      // Still there after the grace time: end it, so that nothing waits forever.
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
      return "terminated after " + std::to_string(wait_s) + " s";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  pid_ = -1;
  if (WIFEXITED(status)) return "exit status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return "killed by signal " + std::to_string(WTERMSIG(status));
  return "ended";
}

void ViewerProcess::send_model(const mjModel* m) {
  send_view_message(fd_, ViewMessageType::kModel, model_bytes(m));
}

bool ViewerProcess::show(const ViewFrame& frame) {
  if (closed_) return false;
  send_view_message(fd_, ViewMessageType::kFrame, encode_view_frame(frame));
  const std::optional<ViewMessage> reply = receive_view_message(fd_);
  if (!reply || reply->type == ViewMessageType::kQuit) {
    closed_ = true;
    return false;
  }
  if (reply->type == ViewMessageType::kError) throw ViewerError(reply->payload);
  if (reply->type != ViewMessageType::kNext) {
    throw ViewerError("viewer connection: unexpected message " +
                      std::to_string(static_cast<int>(reply->type)) + " after a frame");
  }
  return true;
}

void ViewerProcess::finish(const std::string& verdict) {
  if (closed_) return;
  send_view_message(fd_, ViewMessageType::kEnd, verdict);
  // Requests for more frames are moot now; wait for the window to be closed.
  for (;;) {
    const std::optional<ViewMessage> reply = receive_view_message(fd_);
    if (!reply || reply->type == ViewMessageType::kQuit) break;
    if (reply->type == ViewMessageType::kError) throw ViewerError(reply->payload);
  }
  closed_ = true;
}

}  // namespace airtwin
