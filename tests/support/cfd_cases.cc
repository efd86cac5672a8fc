#include "tests/support/cfd_cases.h"

#include <fstream>
#include <nlohmann/json.hpp>

namespace airtwin::testing {

std::string write_cfd_case(const std::string& dir, const std::string& name, double tilt_deg,
                           double s_x, const CfdSynthetic& fn, bool held_out) {
  const int nx = 21, ny = 11;
  nlohmann::json h;
  h["format"] = "airtwin-cfd-floor 1";
  h["case"] = name;
  h["tilt_deg"] = tilt_deg;
  h["held_out"] = held_out;
  h["mesh_level"] = 1;
  h["inlet"] = {{"diameter_m", 0.02}};
  h["stagnation_point_s_m"] = {s_x, 0.0};
  h["ambient"] = {{"k_m2_s2", 1e-3}, {"epsilon_m2_s3", 2e-3}};
  h["grid"] = {{"x0_m", -1.0},
               {"dx_m", 0.1},
               {"nx", nx},
               {"y0_m", 0.0},
               {"dy_m", 0.1},
               {"ny", ny},
               {"heights_m", kCfdTestHeights}};
  h["fields"] = {"ux", "uy", "uz", "k", "epsilon", "p"};
  h["dtype"] = "float32";
  h["byte_order"] = "little";
  h["data_file"] = name + ".f32";
  std::vector<float> data;
  for (double z : kCfdTestHeights) {
    for (int f = 0; f < 6; ++f) {
      for (int iy = 0; iy < ny; ++iy) {
        for (int ix = 0; ix < nx; ++ix) {
          data.push_back(static_cast<float>(fn(-1.0 + 0.1 * ix, 0.1 * iy, z)[f]));
        }
      }
    }
  }
  std::ofstream(dir + "/" + name + ".json") << h.dump(1);
  std::ofstream(dir + "/" + name + ".f32", std::ios::binary)
      .write(reinterpret_cast<const char*>(data.data()),
             static_cast<std::streamsize>(data.size() * sizeof(float)));
  return dir + "/" + name + ".json";
}

}  // namespace airtwin::testing
