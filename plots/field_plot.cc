// PLACEHOLDER (being implemented)
#include "plots/field_plot.h"
#include "common/errors.h"
namespace airtwin::plots {
void write_field_png(const VectorFieldGrid&, const FieldMarks&, const std::string& path) {
  throw InputError(path + ": PNG output not implemented yet");
}
}  // namespace airtwin::plots
