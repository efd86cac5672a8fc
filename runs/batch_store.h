#pragma once
// A batch's folder, and the rule that makes a batch resumable: a run is finished exactly when its
// record file exists, and that file appears all at once (common/atomic_file.h). A batch killed at
// any moment (kill -9 included) and started again finds the runs that finished and redoes the
// others; a run killed half-way left nothing but a temporary file, which the next start deletes.
//
//   DIR/batch.json                              the manifest (runs/batch_manifest.h)
//   DIR/runs/<scenario>/seed-<n>.json           a finished run's record (runs/batch_record.h)
//   DIR/runs/<scenario>/seed-<n>.log.csv        with logs: the trajectory CSV of the run
//   DIR/runs/<scenario>/seed-<n>.decisions.csv  with logs: its decisions
// With logs, both CSV files are committed before the record, so a record always has them.

#include <optional>
#include <string>

#include "runs/batch_manifest.h"
#include "runs/batch_record.h"

namespace airtwin {

/// A finished run's logs (the texts `airtwin run` writes): log.csv and decisions.csv always;
/// the others when not empty.
struct RunLogs {
  std::string log_csv;
  std::string decisions_csv;
  std::string plans_csv;
  std::string nozzle_csv;      ///< the commands sent to the nozzle (models/nozzle_log.h)
  std::string detections_csv;  ///< what the camera pipeline detected (with vision)
};

class BatchStore {
 public:
  /// Opens `dir` for the batch `manifest`, creating it if needed. A new or empty folder gets
  /// batch.json; a folder with batch.json must hold the same batch, else InputError naming the
  /// first difference (BatchManifest::difference); a non-empty folder without batch.json is
  /// refused (InputError), so nothing of another kind is overwritten. Deletes temporaries that a
  /// killed batch left behind.
  BatchStore(std::string dir, const BatchManifest& manifest);

  /// Opens an existing batch folder for reading (its manifest from batch.json). Throws InputError
  /// naming the folder when it is no batch folder.
  static BatchStore open_existing(const std::string& dir);

  const std::string& dir() const { return dir_; }
  const BatchManifest& manifest() const { return manifest_; }

  /// DIR/runs/<scenario>/seed-<n>.json.
  std::string record_path(const RunKey& key) const;

  /// The record of `key` when the run finished; nullopt when it did not. A record file that does
  /// not parse, or that holds another run, counts as not finished and `problem` (if given) says
  /// why, so the caller can report that the run is redone.
  std::optional<RunRecord> load(const RunKey& key, std::string* problem = nullptr) const;

  /// Commits a finished run: its logs (when given), then its record, each atomically. Safe to call
  /// from several threads for different keys. Throws InputError when a file cannot be written.
  void commit(const RunKey& key, const std::string& record_json, const RunLogs* logs) const;

  /// Commits the run `key` of `from` here: its record and, when present, its logs, byte for byte.
  void copy_run(const BatchStore& from, const RunKey& key) const;

 private:
  BatchStore() = default;

  std::string dir_;
  BatchManifest manifest_;
};

}  // namespace airtwin
