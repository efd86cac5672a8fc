#pragma once
// Work items on a few threads, the first failure stopping the rest: a pool of `threads` workers
// that take the next item index until none is left. Items are handed out in increasing order;
// which thread runs an item and the order items finish in are not fixed, so work whose result
// must not depend on them keeps per-item state only (each twin, each trial its own).

#include <cstddef>
#include <functional>

namespace airtwin {

/// Calls work(k) once for every k in [0, n) on min(threads, n) threads (the calling thread alone
/// when that is 1). The first exception a call throws stops handing out items; calls under way
/// finish; then it is rethrown. `work` must be safe to call from several threads at once.
void parallel_for(size_t n, int threads, const std::function<void(size_t)>& work);

}  // namespace airtwin
