// Fuzz target: the nozzle command log (models/nozzle_log.h) that `trajectories --nozzle` reads
// and `run` and `render` write. What the reader accepts, the writer must write and the lookup of
// the command in force must answer for any time.

#include <cstddef>
#include <cstdint>
#include <limits>

#include "fuzz/fuzz_support.h"
#include "models/nozzle_log.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] {
    const NozzleLog log = parse_nozzle_log(text, "nozzle.csv");
    (void)nozzle_log_csv(log.commands);
    const double inf = std::numeric_limits<double>::infinity();
    for (double t : {-inf, -1.0, 0.0, 0.5, 1e9, inf, log.commands.front().t_s}) {
      const long i = log.index_at(t);
      if (i >= 0) (void)log.where(static_cast<size_t>(i));
    }
  });
  return 0;
}
