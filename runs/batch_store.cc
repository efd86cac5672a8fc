#include "runs/batch_store.h"

#include <filesystem>
#include <utility>

#include "common/atomic_file.h"
#include "common/csv.h"
#include "common/errors.h"

namespace airtwin {
namespace fs = std::filesystem;

namespace {

// The logs a run keeps only when it has them, by file suffix (RunLogs).
constexpr std::pair<const char*, std::string RunLogs::*> kOptionalLogs[] = {
    {".plans.csv", &RunLogs::plans_csv},
    {".nozzle.csv", &RunLogs::nozzle_csv},
    {".detections.csv", &RunLogs::detections_csv}};

std::string manifest_path(const std::string& dir) { return dir + "/batch.json"; }

// The files of a run beside its record: DIR/runs/<scenario>/seed-<n><suffix>.
std::string run_file(const std::string& dir, const RunKey& key, const char* suffix) {
  return dir + "/runs/" + key.stem() + suffix;
}

void make_folder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the folder: " + ec.message());
}

}  // namespace

BatchStore::BatchStore(std::string dir, const BatchManifest& manifest)
    : dir_(std::move(dir)), manifest_(manifest) {
  std::error_code ec;
  const std::string path = manifest_path(dir_);
  if (fs::exists(path, ec)) {
    // A started batch: only the same batch may continue here.
    const BatchManifest found = BatchManifest::parse(read_text_file(path), path);
    const std::string diff = found.difference(manifest_, /*ignore_shard=*/false);
    if (!diff.empty()) {
      throw InputError(path + ": this folder holds a batch started with other arguments (" + diff +
                       ", there vs now); start it again with the same arguments or use another "
                       "folder");
    }
  } else {
    // A new batch: only in a new or empty folder, so that nothing else is overwritten.
    if (fs::exists(dir_, ec) && !fs::is_empty(dir_, ec)) {
      throw InputError(dir_ +
                       ": the folder is not empty and holds no batch.json; give a new or "
                       "empty folder");
    }
    make_folder(dir_);
    write_file_atomically(path, manifest_.to_json());
  }
  make_folder(dir_ + "/runs");
  remove_stale_temp_files(dir_);
}

BatchStore BatchStore::open_existing(const std::string& dir) {
  const std::string path = manifest_path(dir);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw InputError(dir + ": not a batch folder (no batch.json; 'airtwin batch --out' makes one)");
  }
  BatchStore store;
  store.dir_ = dir;
  store.manifest_ = BatchManifest::parse(read_text_file(path), path);
  return store;
}

std::string BatchStore::record_path(const RunKey& key) const {
  return run_file(dir_, key, ".json");
}

std::optional<RunRecord> BatchStore::load(const RunKey& key, std::string* problem) const {
  const std::string path = record_path(key);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  try {
    RunRecord r = parse_record(read_text_file(path), path);
    if (r.key != key) {
      throw InputError(path + ": holds the record of " + r.key.label() + ", not " + key.label());
    }
    return r;
  } catch (const InputError& e) {
    if (problem) *problem = e.what();
    return std::nullopt;
  }
}

void BatchStore::commit(const RunKey& key, const std::string& record_json,
                        const RunLogs* logs) const {
  make_folder(dir_ + "/runs/" + key.scenario);
  // Logs first: the record is what marks the run finished.
  if (logs) {
    write_file_atomically(run_file(dir_, key, ".log.csv"), logs->log_csv);
    write_file_atomically(run_file(dir_, key, ".decisions.csv"), logs->decisions_csv);
    for (const auto& [suffix, text] : kOptionalLogs) {
      if (!(logs->*text).empty()) write_file_atomically(run_file(dir_, key, suffix), logs->*text);
    }
  }
  write_file_atomically(record_path(key), record_json);
}

void BatchStore::copy_run(const BatchStore& from, const RunKey& key) const {
  std::optional<RunLogs> logs;
  std::error_code ec;
  const std::string log = run_file(from.dir_, key, ".log.csv");
  if (fs::is_regular_file(log, ec)) {
    logs = RunLogs{};
    logs->log_csv = read_text_file(log);
    logs->decisions_csv = read_text_file(run_file(from.dir_, key, ".decisions.csv"));
    // Optional: a batch made before a log existed, or a run without vision, has none.
    for (const auto& [suffix, text] : kOptionalLogs) {
      const std::string path = run_file(from.dir_, key, suffix);
      if (fs::is_regular_file(path, ec)) (*logs).*text = read_text_file(path);
    }
  }
  commit(key, read_text_file(from.record_path(key)), logs ? &*logs : nullptr);
}

}  // namespace airtwin
