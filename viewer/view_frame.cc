#include "viewer/view_frame.h"

#include <cstring>
#include <memory>
#include <type_traits>

#include "common/errors.h"

namespace airtwin {
namespace {

// Appends plain values and length-prefixed arrays to a byte string.
class Writer {
 public:
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <typename T>
  void array(const std::vector<T>& v) {
    value<uint64_t>(v.size());
    if (!v.empty()) out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void text(const std::string& s) {
    value<uint64_t>(s.size());
    out_.append(s);
  }
  void point(const Eigen::Vector2d& p) {
    value(p.x());
    value(p.y());
  }
  void points(const std::vector<Eigen::Vector2d>& ps) {
    value<uint64_t>(ps.size());
    for (const auto& p : ps) point(p);
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

// Reads what Writer wrote, checking every length against the bytes left.
class Reader {
 public:
  explicit Reader(std::string_view in) : in_(in) {}
  template <typename T>
  T value() {
    T v;
    need(sizeof(T), "a value");
    std::memcpy(&v, in_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  // A count of items of `item_size` bytes each that must fit in the bytes left.
  size_t count(size_t item_size, const char* what) {
    const uint64_t n = value<uint64_t>();
    if (item_size > 0 && n > (in_.size() - at_) / item_size) {
      throw InputError(std::string("view frame: ") + what + " count " + std::to_string(n) +
                       " runs past the end of the message");
    }
    return static_cast<size_t>(n);
  }
  template <typename T>
  std::vector<T> array(const char* what) {
    std::vector<T> v(count(sizeof(T), what));
    if (!v.empty()) std::memcpy(v.data(), in_.data() + at_, v.size() * sizeof(T));
    at_ += v.size() * sizeof(T);
    return v;
  }
  std::string text(const char* what) {
    const size_t n = count(1, what);
    std::string s(in_.substr(at_, n));
    at_ += n;
    return s;
  }
  Eigen::Vector2d point() {
    const double x = value<double>();
    return {x, value<double>()};
  }
  std::vector<Eigen::Vector2d> points(const char* what) {
    std::vector<Eigen::Vector2d> ps(count(2 * sizeof(double), what));
    for (auto& p : ps) p = point();
    return ps;
  }
  void finish() const {
    if (at_ != in_.size()) {
      throw InputError("view frame: " + std::to_string(in_.size() - at_) +
                       " bytes left over after the frame");
    }
  }

 private:
  void need(size_t n, const char* what) const {
    if (in_.size() - at_ < n) {
      throw InputError(std::string("view frame: truncated, ") + what + " missing");
    }
  }
  std::string_view in_;
  size_t at_ = 0;
};

}  // namespace

std::string encode_view_frame(const ViewFrame& f) {
  Writer w;
  w.value(f.index);
  w.array(f.kinematics.reals);
  w.array(f.kinematics.ints);
  const ViewOverlay& o = f.overlay;
  w.points(o.path_W);
  w.points(o.path_references_W);
  w.points(o.current_references_W);
  w.value<uint64_t>(o.zones.size());
  for (const ViewZone& z : o.zones) {
    w.point(z.centre_W);
    w.value(z.radius_m);
    w.text(z.label);
  }
  w.value<uint8_t>(o.stagnation_W ? 1 : 0);
  w.point(o.stagnation_W.value_or(Eigen::Vector2d::Zero()));
  w.value<uint64_t>(o.air.size());
  for (const ViewArrow& a : o.air) {
    w.point(a.p_W);
    w.point(a.v_W);
  }
  w.text(o.caption);
  return w.take();
}

ViewFrame decode_view_frame(std::string_view bytes) {
  Reader r(bytes);
  ViewFrame f;
  f.index = r.value<int64_t>();
  f.kinematics.reals = r.array<mjtNum>("kinematic reals");
  f.kinematics.ints = r.array<int>("kinematic integers");
  ViewOverlay& o = f.overlay;
  o.path_W = r.points("path point");
  o.path_references_W = r.points("reference point");
  o.current_references_W = r.points("current reference");
  o.zones.resize(r.count(3 * sizeof(double) + sizeof(uint64_t), "zone"));
  for (ViewZone& z : o.zones) {
    z.centre_W = r.point();
    z.radius_m = r.value<double>();
    z.label = r.text("zone label");
  }
  const bool has_s = r.value<uint8_t>() != 0;
  const Eigen::Vector2d s = r.point();
  if (has_s) o.stagnation_W = s;
  o.air.resize(r.count(4 * sizeof(double), "air arrow"));
  for (ViewArrow& a : o.air) {
    a.p_W = r.point();
    a.v_W = r.point();
  }
  o.caption = r.text("caption");
  r.finish();
  return f;
}

std::string model_bytes(const mjModel* m) {
  std::string bytes(static_cast<size_t>(mj_sizeModel(m)), '\0');
  mj_saveModel(m, nullptr, bytes.data(), static_cast<int>(bytes.size()));
  return bytes;
}

ModelPtr model_from_bytes(std::string_view bytes) {
  install_mujoco_handlers();
  // MuJoCo reads past the end of a short buffer (an engine error, not a warning): check that
  // there is at least an MJB header, whose first int is MuJoCo's ID 54321, before it looks.
  constexpr int kMjbId = 54321;
  int id = 0;
  if (bytes.size() >= 4 * sizeof(int)) std::memcpy(&id, bytes.data(), sizeof(id));
  if (id != kMjbId) throw InputError("viewer: the model it was sent is not an MJB model");
  // MuJoCo 2.2 reads an MJB from a file or from a file of a virtual file system.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "model.mjb";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(bytes.size())) != 0) {
    throw InputError("viewer: cannot hold the model's " + std::to_string(bytes.size()) +
                     " bytes in MuJoCo's virtual file system");
  }
  std::memcpy(vfs->filedata[vfs->nfile - 1], bytes.data(), bytes.size());
  ModelPtr m(mj_loadModel(name, vfs.get()));
  mj_deleteVFS(vfs.get());
  if (!m) throw InputError("viewer: MuJoCo cannot read the model it was sent");
  return m;
}

}  // namespace airtwin
