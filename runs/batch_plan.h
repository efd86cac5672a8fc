#pragma once
// What a batch runs: every scenario x seed, each run named by a stable key (scenario name, seed)
// that fixes its result (runs/scenario_run.h: a run depends on its scenario, options and seed
// only), and how the runs are split into shards for a cluster's job array.
//
// Order. Runs are ordered by scenario name, then seed; every output of a batch follows that order,
// whatever order the runs finished in. Shards. Shard I of N (0-based, 0 <= I < N, so that a Slurm
// array --array=0-(N-1) passes its task id as it is) takes every N-th run of that order starting
// at the I-th: each shard gets a share of every scenario, so shards take about equally long.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scenes/scenario.h"

namespace airtwin {

/// Shard `index` of `count` (0 <= index < count).
struct Shard {
  int index = 0;
  int count = 1;
  bool operator==(const Shard&) const = default;
};

/// Parses a shard "I/N" (integers, 0 <= I < N <= 100000). Throws FieldError (batch.shard).
Shard parse_shard(const std::string& text);

/// One run: which scenario (by name), which seed.
struct RunKey {
  std::string scenario;
  uint64_t seed = 0;

  /// "<scenario>/seed-<seed>": where the run's files live under a batch's runs/ folder.
  std::string stem() const;
  /// "<scenario> seed <seed>" for messages.
  std::string label() const;
  auto operator<=>(const RunKey&) const = default;
};

struct BatchScenario {
  Scenario scenario;
  std::string file;          ///< the path it was read from, as given
  std::string content_hash;  ///< content_hash() of the file's bytes
};

struct BatchPlan {
  std::vector<BatchScenario> scenarios;  ///< sorted by name, names unique
  uint64_t first_seed = 1;
  int seed_count = 1;
  Shard shard;

  /// Every scenario x seed of the batch in (scenario, seed) order, whatever the shard.
  std::vector<RunKey> all_runs() const;
  /// This shard's runs, in the same order (all_runs() when the shard is 0/1).
  std::vector<RunKey> shard_runs() const;
  /// The scenarios' names, in order.
  std::vector<std::string> names() const;
  /// The scenario named `name` (which must be in the plan; AIRTWIN_DEMAND otherwise).
  const BatchScenario& scenario(const std::string& name) const;
};

/// The runs of scenarios `names` (sorted) x seeds first_seed .. first_seed + seed_count - 1 that
/// fall to `shard`: every shard.count-th of the (scenario, seed) order from the shard.index-th.
std::vector<RunKey> plan_runs(const std::vector<std::string>& names, uint64_t first_seed,
                              int seed_count, Shard shard);

/// Reads the scenario files and makes the plan of seeds first_seed .. first_seed + seed_count - 1.
/// Throws FieldError (batch.seed_count, batch.first_seed) for a seed count outside [1, 1000000] or
/// seeds past 2^64 - 1; InputError when a file cannot be read or parsed (as read_scenario), when
/// two files give the same scenario name, or when a name cannot be a folder name (letters, digits,
/// '_', '-' and inner '.' only).
BatchPlan make_batch_plan(const std::vector<std::string>& files, uint64_t first_seed,
                          int seed_count, Shard shard);

/// A 64-bit FNV-1a hash of `bytes` as 16 hex digits: says whether a file changed between two
/// starts of a batch (not a cryptographic hash).
std::string content_hash(std::string_view bytes);

}  // namespace airtwin
