#pragma once
// The shipped CFD cases (data/cfd/, docs/cfd.md), read once per test process (header-only; the
// tests that include it link airtwin_models or a library above it).

#include <memory>

#include "models/cfd_field.h"

namespace airtwin::testing {

/// The shipped CFD cases, read once per process.
inline std::shared_ptr<const CfdField> shipped_cfd() {
  static const auto cfd =
      std::make_shared<const CfdField>(CfdField::read_dir(AIRTWIN_SOURCE_DIR "/data/cfd"));
  return cfd;
}

}  // namespace airtwin::testing
