// model.json: what identify writes is what later commands read back, and bad files are refused
// with the key named.

#include "models/identified_model.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "common/errors.h"

namespace airtwin {
namespace {

IdentifiedModel tracer_model() {
  IdentifiedModel m;
  m.object = "tracer";
  m.method = "robust-esindy";
  m.coefficients[0] = -8.53;
  m.coefficients[1] = -2.66;
  m.coefficients[2] = 4.26;
  m.discrete[1] = 0.9335;
  m.inclusion.setConstant(0.2);
  m.r2 = 0.93;
  m.end_position_mape_pct = 9.0;
  m.end_position_mape_by_tilt_pct = {{0.0, 8.0}, {22.5, 10.0}};
  m.n_samples = 4000;
  m.n_dropped = 120;
  m.dt_s = 0.025;
  m.source = "data.csv";
  return m;
}

TEST(IdentifiedModel, TheFileHasTheDocumentedKeysInOrder) {
  const nlohmann::ordered_json j =
      nlohmann::ordered_json::parse(identified_model_json(tracer_model()));
  const char* first[] = {"object",
                         "method",
                         "terms",
                         "coefficients",
                         "discrete_coefficients",
                         "inclusion_probability",
                         "r2",
                         "end_position_mape",
                         "n_samples",
                         "n_dropped"};
  auto it = j.begin();
  for (const char* key : first) {
    ASSERT_NE(it, j.end());
    EXPECT_EQ(it.key(), key);
    ++it;
  }
  EXPECT_EQ(j["terms"][4], "v*vair");
  EXPECT_EQ(j["eq8"]["xi2"], 4.26);
  EXPECT_EQ(j["end_position_mape_by_tilt"]["22.5"], 10.0);
}

TEST(IdentifiedModel, RoundTripsExactly) {
  const IdentifiedModel m = tracer_model();
  const IdentifiedModel back = parse_identified_model_json(identified_model_json(m), "m.json");
  EXPECT_EQ(back.coefficients, m.coefficients);
  EXPECT_EQ(back.discrete, m.discrete);
  EXPECT_EQ(back.object, "tracer");
  EXPECT_EQ(*back.end_position_mape_pct, 9.0);
  const ObjectDynamics d = back.eq8();
  EXPECT_EQ(d.xi1, -2.66);
  EXPECT_EQ(d.xi2, 4.26);
  EXPECT_EQ(d.xi3, -8.53);
}

TEST(IdentifiedModel, ExtraTermsAreNotEq8) {
  IdentifiedModel m = tracer_model();
  m.coefficients[4] = 0.5;  // v*vair
  EXPECT_FALSE(m.is_eq8());
  try {
    m.eq8();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("v*vair"), std::string::npos);
  }
  const auto j = nlohmann::json::parse(identified_model_json(m));
  EXPECT_TRUE(j["eq8"].is_null());
}

// The library the regression was allowed (--terms) is kept; a file without the key (written
// before it existed) used all ten terms; a wrong list names the key.
TEST(IdentifiedModel, LibraryRoundTripsAndDefaultsToAllTerms) {
  IdentifiedModel m = tracer_model();
  m.library = {"1", "v", "vair"};
  EXPECT_EQ(parse_identified_model_json(identified_model_json(m), "m.json").library, m.library);
  auto j = nlohmann::ordered_json::parse(identified_model_json(m));
  j.erase("library");
  EXPECT_EQ(parse_identified_model_json(j.dump(), "m.json").library,
            std::vector<std::string>(kTermNames.begin(), kTermNames.end()));
  j["library"] = {"1", "w"};
  EXPECT_THROW(parse_identified_model_json(j.dump(), "m.json"), InputError);
  j["library"] = nlohmann::ordered_json::array();
  EXPECT_THROW(parse_identified_model_json(j.dump(), "m.json"), InputError);
}

TEST(IdentifiedModel, BadFilesNameTheKey) {
  auto error_of = [](const std::string& text) -> std::string {
    try {
      parse_identified_model_json(text, "m.json");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of("not json").find("not a JSON object"), std::string::npos);
  EXPECT_NE(error_of("{}").find("'terms'"), std::string::npos);
  auto j = nlohmann::ordered_json::parse(identified_model_json(tracer_model()));
  j["terms"][3] = "v2";
  EXPECT_NE(error_of(j.dump()).find("'terms'[3]"), std::string::npos);
  j = nlohmann::ordered_json::parse(identified_model_json(tracer_model()));
  j["coefficients"][1] = "fast";
  EXPECT_NE(error_of(j.dump()).find("coefficients[1]"), std::string::npos);
  j["coefficients"] = {1, 2};
  EXPECT_NE(error_of(j.dump()).find("array of 10"), std::string::npos);
  j = nlohmann::ordered_json::parse(identified_model_json(tracer_model()));
  j.erase("object");
  EXPECT_NE(error_of(j.dump()).find("'object'"), std::string::npos);
  EXPECT_THROW(read_identified_model("/nonexistent/model.json"), InputError);
}

}  // namespace
}  // namespace airtwin
