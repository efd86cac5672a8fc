#include "sim/kinematic_state.h"

#include <algorithm>
#include <string>

#include "common/errors.h"

namespace airtwin {
namespace {

// One array of mjData and its length for a model.
template <typename T>
struct Field {
  T* mjData::*array;
  int (*count)(const mjModel* m);
};

// The arrays mjv_updateScene reads for the categories drawn (besides the time): the one list of
// them, in the order they are flattened.
const Field<mjtNum> kRealFields[] = {
    {&mjData::qpos, [](const mjModel* m) { return m->nq; }},
    {&mjData::mocap_pos, [](const mjModel* m) { return 3 * m->nmocap; }},
    {&mjData::mocap_quat, [](const mjModel* m) { return 4 * m->nmocap; }},
    {&mjData::xpos, [](const mjModel* m) { return 3 * m->nbody; }},
    {&mjData::xquat, [](const mjModel* m) { return 4 * m->nbody; }},
    {&mjData::xmat, [](const mjModel* m) { return 9 * m->nbody; }},
    {&mjData::xipos, [](const mjModel* m) { return 3 * m->nbody; }},
    {&mjData::ximat, [](const mjModel* m) { return 9 * m->nbody; }},
    {&mjData::subtree_com, [](const mjModel* m) { return 3 * m->nbody; }},
    {&mjData::xanchor, [](const mjModel* m) { return 3 * m->njnt; }},
    {&mjData::xaxis, [](const mjModel* m) { return 3 * m->njnt; }},
    {&mjData::geom_xpos, [](const mjModel* m) { return 3 * m->ngeom; }},
    {&mjData::geom_xmat, [](const mjModel* m) { return 9 * m->ngeom; }},
    {&mjData::site_xpos, [](const mjModel* m) { return 3 * m->nsite; }},
    {&mjData::site_xmat, [](const mjModel* m) { return 9 * m->nsite; }},
    {&mjData::cam_xpos, [](const mjModel* m) { return 3 * m->ncam; }},
    {&mjData::cam_xmat, [](const mjModel* m) { return 9 * m->ncam; }},
    {&mjData::light_xpos, [](const mjModel* m) { return 3 * m->nlight; }},
    {&mjData::light_xdir, [](const mjModel* m) { return 3 * m->nlight; }},
    {&mjData::ten_length, [](const mjModel* m) { return m->ntendon; }},
    {&mjData::wrap_xpos, [](const mjModel* m) { return 6 * m->nwrap; }},
};
const Field<int> kIntFields[] = {
    {&mjData::ten_wrapadr, [](const mjModel* m) { return m->ntendon; }},
    {&mjData::ten_wrapnum, [](const mjModel* m) { return m->ntendon; }},
    {&mjData::wrap_obj, [](const mjModel* m) { return 2 * m->nwrap; }},
};

// Total length of `fields` for `m`.
template <typename T, size_t N>
size_t total(const mjModel* m, const Field<T> (&fields)[N]) {
  size_t n = 0;
  for (const Field<T>& f : fields) n += static_cast<size_t>(std::max(f.count(m), 0));
  return n;
}

}  // namespace

KinematicState capture_kinematics(const mjModel* m, const mjData* d) {
  KinematicState state;
  state.reals.reserve(1 + total(m, kRealFields));
  state.ints.reserve(total(m, kIntFields));
  state.reals.push_back(d->time);
  for (const auto& f : kRealFields) {
    const mjtNum* p = d->*f.array;
    state.reals.insert(state.reals.end(), p, p + std::max(f.count(m), 0));
  }
  for (const auto& f : kIntFields) {
    const int* p = d->*f.array;
    state.ints.insert(state.ints.end(), p, p + std::max(f.count(m), 0));
  }
  return state;
}

void restore_kinematics(const mjModel* m, const KinematicState& state, mjData* d) {
  const size_t reals = 1 + total(m, kRealFields), ints = total(m, kIntFields);
  if (state.reals.size() != reals || state.ints.size() != ints) {
    throw InputError("kinematic state: " + std::to_string(state.reals.size()) + " reals and " +
                     std::to_string(state.ints.size()) +
                     " integers, where the model's fields hold " + std::to_string(reals) + " and " +
                     std::to_string(ints) + " (a state of another model)");
  }
  d->time = state.reals[0];
  const mjtNum* r = state.reals.data() + 1;
  for (const auto& f : kRealFields) {
    const int n = std::max(f.count(m), 0);
    std::copy_n(r, n, d->*f.array);
    r += n;
  }
  const int* i = state.ints.data();
  for (const auto& f : kIntFields) {
    const int n = std::max(f.count(m), 0);
    std::copy_n(i, n, d->*f.array);
    i += n;
  }
}

void mirror_kinematics(const mjModel* m, const mjData* src, mjData* dst) {
  dst->time = src->time;
  for (const auto& f : kRealFields) {
    std::copy_n(src->*f.array, std::max(f.count(m), 0), dst->*f.array);
  }
  for (const auto& f : kIntFields) {
    std::copy_n(src->*f.array, std::max(f.count(m), 0), dst->*f.array);
  }
}

}  // namespace airtwin
