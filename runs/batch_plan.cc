#include "runs/batch_plan.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <limits>

#include "common/csv.h"
#include "common/errors.h"

namespace airtwin {
namespace {

// A whole-string non-negative integer, or -1.
long long parse_count(std::string_view text) {
  long long v = -1;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || v < 0) return -1;
  return v;
}

// A scenario name becomes a folder name under runs/: no separators, nothing hidden or special.
bool usable_as_folder_name(const std::string& name) {
  if (name.empty() || name.size() > 100 || name.front() == '.' || name.back() == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.';
  });
}

}  // namespace

Shard parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  const long long index = slash == std::string::npos ? -1 : parse_count(text.substr(0, slash));
  const long long count = slash == std::string::npos ? -1 : parse_count(text.substr(slash + 1));
  if (index < 0 || count < 1 || count > 100000) {
    throw FieldError("batch.shard",
                     "expected I/N with 0 <= I < N <= 100000 (0-based), got '" + text + "'");
  }
  if (index >= count) {
    throw FieldError("batch.shard", "the shard index is 0-based, so I must be below N = " +
                                        std::to_string(count) + ", got '" + text + "'");
  }
  return {static_cast<int>(index), static_cast<int>(count)};
}

std::string RunKey::stem() const { return scenario + "/seed-" + std::to_string(seed); }

std::string RunKey::label() const { return scenario + " seed " + std::to_string(seed); }

std::vector<RunKey> plan_runs(const std::vector<std::string>& names, uint64_t first_seed,
                              int seed_count, Shard shard) {
  // The whole order is scenario-major; the shard keeps every count-th run from its index.
  std::vector<RunKey> runs;
  size_t k = 0;
  for (const std::string& name : names) {
    for (int i = 0; i < seed_count; ++i, ++k) {
      if (k % static_cast<size_t>(shard.count) != static_cast<size_t>(shard.index)) continue;
      runs.push_back({name, first_seed + static_cast<uint64_t>(i)});
    }
  }
  return runs;
}

std::vector<RunKey> BatchPlan::all_runs() const {
  return plan_runs(names(), first_seed, seed_count, Shard{});
}

std::vector<RunKey> BatchPlan::shard_runs() const {
  return plan_runs(names(), first_seed, seed_count, shard);
}

std::vector<std::string> BatchPlan::names() const {
  std::vector<std::string> out;
  for (const BatchScenario& s : scenarios) out.push_back(s.scenario.name);
  return out;
}

const BatchScenario& BatchPlan::scenario(const std::string& name) const {
  const auto it = std::find_if(scenarios.begin(), scenarios.end(),
                               [&](const BatchScenario& s) { return s.scenario.name == name; });
  AIRTWIN_DEMAND(it != scenarios.end());
  return *it;
}

BatchPlan make_batch_plan(const std::vector<std::string>& files, uint64_t first_seed,
                          int seed_count, Shard shard) {
  // Seeds: flags first, before any file is read.
  if (seed_count < 1 || seed_count > 1000000) {
    throw FieldError("batch.seed_count",
                     "expected a count in [1, 1000000], got " + std::to_string(seed_count));
  }
  if (first_seed > std::numeric_limits<uint64_t>::max() - static_cast<uint64_t>(seed_count - 1)) {
    throw FieldError("batch.first_seed", "the seeds would pass 2^64 - 1");
  }
  AIRTWIN_DEMAND(shard.count >= 1 && shard.index >= 0 && shard.index < shard.count);
  if (files.empty()) throw FieldError("batch.scenarios", "give at least one scenario file");

  BatchPlan plan;
  plan.first_seed = first_seed;
  plan.seed_count = seed_count;
  plan.shard = shard;
  // Each file read once: its bytes are both parsed and hashed.
  for (const std::string& file : files) {
    BatchScenario s;
    const std::string text = read_text_file(file);
    s.scenario = parse_scenario(text, file);
    s.file = file;
    s.content_hash = content_hash(text);
    if (!usable_as_folder_name(s.scenario.name)) {
      throw InputError(file + ": the scenario name '" + s.scenario.name +
                       "' names the batch's folder for its runs: use letters, digits, '_', '-' "
                       "and inner '.' only");
    }
    for (const BatchScenario& other : plan.scenarios) {
      if (other.scenario.name == s.scenario.name) {
        throw InputError(file + ": the scenario name '" + s.scenario.name + "' is also that of " +
                         other.file + "; a batch needs distinct names");
      }
    }
    plan.scenarios.push_back(std::move(s));
  }
  std::sort(plan.scenarios.begin(), plan.scenarios.end(),
            [](const BatchScenario& a, const BatchScenario& b) {
              return a.scenario.name < b.scenario.name;
            });
  return plan;
}

std::string content_hash(std::string_view bytes) {
  uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a 64: offset basis, then xor and multiply per byte
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

}  // namespace airtwin
