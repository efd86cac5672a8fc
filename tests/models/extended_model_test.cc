#include "models/extended_model.h"

#include <gtest/gtest.h>

#include <string>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

ExtendedModel example() {
  ExtendedModel m;
  m.objects["tracer"] = kTracerDynamics;
  m.nozzle.transit_delay_s = 0.25;
  set_extension_values(&m.extensions, "field_scale", {1.2});
  set_extension_values(&m.extensions, "floor_slope", {3.0, -45.0});
  m.objects["cotton"] = kCottonDynamics;
  set_extension_values(&m.extensions, "linearised_drag@tracer", {0.45});
  m.source = "data.csv";
  return m;
}

TEST(ExtendedModel, RoundTripsItsJson) {
  const std::string text = extended_model_json(example());
  EXPECT_TRUE(looks_like_extended_model(text));
  EXPECT_FALSE(looks_like_extended_model("{\"object\": \"tracer\"}"));
  const ExtendedModel back = parse_extended_model_json(text, "m.json");
  EXPECT_EQ(back.objects.at("tracer").xi3, kTracerDynamics.xi3);
  EXPECT_EQ(back.nozzle.transit_delay_s, 0.25);
  EXPECT_DOUBLE_EQ(back.extensions.field_scale, 1.2);
  EXPECT_NEAR(back.extensions.slope_direction_rad, deg_to_rad(-45.0), 1e-15);
  EXPECT_EQ(active_extensions(back.extensions),
            (std::vector<std::string>{"floor_slope", "field_scale", "linearised_drag@tracer"}));
  EXPECT_EQ(back.extensions.object_for("tracer").drag_intercept_share, 0.45);
  EXPECT_EQ(back.extensions.object_for("cotton").drag_intercept_share, 0.0);
  EXPECT_EQ(extended_model_json(back), text);
}

TEST(ExtendedModel, BadFilesNameWhatIsWrong) {
  const std::string good = extended_model_json(example());
  auto error_of = [](const std::string& text) {
    try {
      parse_extended_model_json(text, "m.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("not json").find("m.json: not JSON"), std::string::npos);
  // A number past double's range: nlohmann's out_of_range, not a parse error
  // (fuzz/extended_model_fuzz.cc).
  EXPECT_NE(error_of("{\"version\": 1e999}").find("m.json: not JSON"), std::string::npos);
  std::string t = good;
  t.replace(t.find("field_scale"), 11, "field_scalf");
  EXPECT_NE(error_of(t).find("unknown effect 'field_scalf'"), std::string::npos);
  t = good;
  t.replace(t.find("\"factor\": 1.2"), 13, "\"factor\": -1");
  EXPECT_NE(error_of(t).find("field_scale.factor"), std::string::npos) << error_of(t);
  t = good;
  t.replace(t.find("linearised_drag@tracer"), 22, "linearised_drag@glass");
  EXPECT_NE(error_of(t).find("extensions.linearised_drag@glass: no object type 'glass'"),
            std::string::npos)
      << error_of(t);
  t = good;
  t.replace(t.find("linearised_drag@tracer"), 22, "field_scale@tracer");
  EXPECT_NE(error_of(t).find("field_scale acts on the rig"), std::string::npos) << error_of(t);
  t = good;
  t.replace(t.find("\"xi2\""), 5, "\"xj2\"");
  EXPECT_NE(error_of(t).find("objects.cotton: missing key 'xi2'"), std::string::npos)
      << error_of(t);
}

TEST(ExtendedModel, ScaledTableScalesTheAirSpeed) {
  const FieldTable& base = FieldTable::constructed_table();
  const FieldTable scaled = scaled_field_table(base, 1.3);
  for (double r : {0.1, 0.4, 0.9}) {
    EXPECT_NEAR(scaled.at(1, 37).speed(r), 1.3 * base.at(1, 37).speed(r), 1e-12);
  }
  EXPECT_THROW(scaled_field_table(base, 0.0), InputError);
}

}  // namespace
}  // namespace airtwin
