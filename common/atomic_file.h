#pragma once
// Files that are either entirely there or not there at all, whatever happens to the process
// (kill -9, a Slurm time limit) or, within what the filesystem promises, to the machine: the
// bytes go to a temporary file beside the target, are flushed to the disk (fsync), and the
// temporary is renamed over the target (rename(2) is atomic within one filesystem); the folder is
// then flushed so the new name itself survives a crash. A reader sees the old file or the new
// one, never a part.
//
// Temporary files are named "<target>.tmp.<pid>.<counter>" (kTempMarker inside); a process killed
// between write and rename leaves one behind, which remove_stale_temp_files clears.

#include <string>
#include <string_view>

namespace airtwin {

/// What every temporary file's name contains (after the target's file name).
inline constexpr std::string_view kTempMarker = ".tmp.";

/// Writes `bytes` to `path` atomically as described above (the folder must exist). Safe to call
/// from several threads for different paths; two writers of one path leave one complete version.
/// Throws InputError naming the path and the system's reason when a step fails (the temporary is
/// removed then).
void write_file_atomically(const std::string& path, std::string_view bytes);

/// Deletes the temporary files write_file_atomically leaves behind when killed, in `dir` and
/// below; returns how many. A missing folder has none. Call it only when no writer is running in
/// that folder.
int remove_stale_temp_files(const std::string& dir);

}  // namespace airtwin
