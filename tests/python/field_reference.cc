// The air field evaluated from C++, for the Python tests: the same library function the module
// binds (OrientedField::velocities), called on points read as hexadecimal floats, so that the
// two routes can be compared to the last bit.
// Usage: field_reference TABLE|default PAN_DEG TILT_DEG < points (lines "x y", %a) > "vx vy" (%a)

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "common/errors.h"
#include "common/units.h"
#include "models/air_field.h"
#include "models/field_model_file.h"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: field_reference TABLE|default PAN_DEG TILT_DEG < points\n");
    return 2;
  }
  using namespace airtwin;
  try {
    const std::string table = argv[1];
    const AirFieldModel model =
        table == "default" ? AirFieldModel::fitted_to_cfd() : read_air_field_model(table);
    const NozzleOrientation o{deg_to_rad(std::strtod(argv[2], nullptr)),
                              deg_to_rad(std::strtod(argv[3], nullptr))};
    std::vector<double> xy;
    double x, y;
    while (std::scanf("%la %la", &x, &y) == 2) {
      xy.push_back(x);
      xy.push_back(y);
    }
    const Eigen::Index n = static_cast<Eigen::Index>(xy.size() / 2);
    Eigen::Matrix2Xd v(2, n);
    model.at(o).velocities(Eigen::Map<const Eigen::Matrix2Xd>(xy.data(), 2, n), v);
    for (Eigen::Index i = 0; i < n; ++i) std::printf("%a %a\n", v(0, i), v(1, i));
  } catch (const InputError& e) {
    std::fprintf(stderr, "field_reference: %s\n", e.what());
    return 1;
  }
  return 0;
}
