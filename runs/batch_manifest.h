#pragma once
// The manifest of a batch (DIR/batch.json): everything a batch's results depend on - the scenarios
// (name and a hash of the file's bytes), the seeds, the settings the command turned into run
// options (perception, field table, models, effects, the program's own hash, ...) - and which
// shard of it the folder holds. It is written when the folder is new; a later start in the same
// folder must present the same manifest, so that a resumed batch never mixes results of other
// arguments. It is also what batch-merge checks to know that folders are shards of one batch.
//
// File paths are kept for people but ignored in comparisons (under the key "file" at any depth):
// `scenes/line.yaml` and `./scenes/line.yaml`, or one path on the cluster and another here, name
// the same content when their hashes agree.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "runs/batch_plan.h"

namespace airtwin {

struct BatchManifest {
  struct Entry {
    std::string name;
    std::string file;
    std::string content_hash;
  };
  std::vector<Entry> scenarios;  ///< sorted by name
  uint64_t first_seed = 1;
  int seed_count = 1;
  Shard shard;
  /// What the command's flags set (free-form JSON object, compared as a whole but for "file").
  nlohmann::ordered_json settings = nlohmann::ordered_json::object();

  /// The manifest of `plan` with `settings`.
  static BatchManifest of_plan(const BatchPlan& plan, nlohmann::ordered_json settings);

  /// Every run of the batch in (scenario, seed) order, and this shard's (as BatchPlan's).
  std::vector<RunKey> all_runs() const;
  std::vector<RunKey> shard_runs() const;

  /// batch.json's text (2-space indented): format, scenarios, seeds, shard, settings.
  std::string to_json() const;
  /// Reads batch.json's text; throws InputError naming `source` when it is not a manifest.
  static BatchManifest parse(const std::string& text, const std::string& source);

  /// What results depend on, as JSON: format, scenarios (names and hashes), seeds, settings, and
  /// with `with_shard` the shard; no file paths.
  nlohmann::ordered_json identity(bool with_shard) const;

  /// Empty when `other` is the same batch, else the first difference as "KEY: A vs B" (JSON
  /// pointer of the key, the values as JSON). With `ignore_shard`, shards of one batch agree.
  std::string difference(const BatchManifest& other, bool ignore_shard) const;
};

}  // namespace airtwin
