// Fuzz target: a batch's manifest, batch.json (runs/batch_manifest.h), which a resumed batch and
// batch-merge read and compare. What the reader accepts, the writer must write.

#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_support.h"
#include "runs/batch_manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace airtwin;
  const std::string text = fuzz::text_of(data, size);
  fuzz::expect_input_error([&] {
    const BatchManifest manifest = BatchManifest::parse(text, "fuzz.json");
    (void)manifest.to_json();
    (void)manifest.difference(manifest, /*ignore_shard=*/false);
  });
  return 0;
}
