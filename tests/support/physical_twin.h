#pragma once
// The physical twin every command builds by default (docs/twin.md): the shipped CFD's air and the
// calibrated physical drag of both object types (header-only; the tests that include it link
// airtwin_sim or a library above it).

#include "sim/twin.h"
#include "tests/support/shipped_cfd.h"

namespace airtwin::testing {

inline TwinParameters physical_twin() {
  TwinParameters p;
  p.scene.tracer.use_physical_drag();
  p.scene.cotton.use_physical_drag();
  p.cfd_air = shipped_cfd();
  return p;
}

}  // namespace airtwin::testing
