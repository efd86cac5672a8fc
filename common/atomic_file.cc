#include "common/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include "common/errors.h"

namespace airtwin {
namespace {

std::string system_reason(int err) { return std::strerror(err); }

// Writes all of `bytes` to `fd`, retrying short writes and interrupted calls; errno on failure.
int write_all(int fd, std::string_view bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    done += static_cast<size_t>(n);
  }
  return 0;
}

// Flushes a folder's entries (the rename) to the disk; a filesystem that cannot is not an error.
void sync_folder(const std::filesystem::path& dir) {
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void write_file_atomically(const std::string& path, std::string_view bytes) {
  // A temporary name no other writer uses: this process's id and a process-wide counter.
  static std::atomic<unsigned long long> counter{0};
  const std::string temp = path + std::string(kTempMarker) + std::to_string(::getpid()) + "." +
                           std::to_string(counter++);

  // The bytes, flushed to the disk before the file gets its name.
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw InputError(path + ": cannot create '" + temp + "': " + system_reason(errno));
  int err = write_all(fd, bytes);
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) {
    ::unlink(temp.c_str());
    throw InputError(path + ": write failed: " + system_reason(err));
  }

  // The name: atomically replaces any previous version, then the folder entry is made durable.
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    err = errno;
    ::unlink(temp.c_str());
    throw InputError(path + ": cannot rename '" + temp + "' into place: " + system_reason(err));
  }
  sync_folder(std::filesystem::path(path).parent_path());
}

int remove_stale_temp_files(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return 0;
  // Collect first, then delete: removing entries while iterating is unspecified.
  std::vector<fs::path> stale;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (it->is_regular_file(ec) && name.find(kTempMarker) != std::string::npos) {
      stale.push_back(it->path());
    }
  }
  if (ec) throw InputError(dir + ": cannot list the folder: " + ec.message());
  int removed = 0;
  for (const fs::path& p : stale) removed += fs::remove(p, ec) ? 1 : 0;
  return removed;
}

}  // namespace airtwin
