// The effects catalogue is one table: indexed by its enum, every entry consistent (examples and
// the nominal values inside the physical range, the fit range inside it too, a size that says
// when the effect is on), and the model's side maps every parameter both ways.

#include "models/effect_catalogue.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "common/errors.h"
#include "models/model_extensions.h"

namespace airtwin {
namespace {

TEST(EffectCatalogue, IndexedByItsEnumWithUniqueNames) {
  std::set<std::string> names;
  for (size_t i = 0; i < kEffectCount; ++i) {
    const EffectSpec& e = effect_catalogue()[i];
    EXPECT_EQ(static_cast<size_t>(e.id), i) << e.name;
    EXPECT_EQ(&effect_spec(e.id), &e);
    EXPECT_EQ(&find_effect(e.name), &e);
    EXPECT_TRUE(names.insert(e.name).second) << e.name;
    EXPECT_FALSE(e.params.empty()) << e.name;
    EXPECT_GT(e.negligible_size, 0.0) << e.name;
  }
}

TEST(EffectCatalogue, ValuesInsideTheirRanges) {
  for (const EffectSpec& e : effect_catalogue()) {
    bool switched = false;
    for (const EffectParameter& p : e.params) {
      SCOPED_TRACE(std::string(e.name) + "." + p.key);
      EXPECT_LT(p.min, p.max);
      EXPECT_NO_THROW(check_effect_value(e, p, p.example));
      EXPECT_NO_THROW(check_effect_value(e, p, p.off));
      EXPECT_LE(p.min, p.fit_min);
      EXPECT_LT(p.fit_min, p.fit_max);
      EXPECT_LE(p.fit_max, p.max);
      EXPECT_THROW(check_effect_value(e, p, p.max + 1.0), InputError);
      switched = switched || p.switches;
    }
    EXPECT_TRUE(switched) << e.name << ": no parameter switches it on";
    // The examples are an effect worth finding; the nominal values are none.
    std::vector<double> example, off;
    for (const EffectParameter& p : e.params) {
      example.push_back(p.example);
      off.push_back(p.off);
    }
    EXPECT_GT(effect_size(e, example), e.negligible_size) << e.name;
    EXPECT_EQ(effect_size(e, off), 0.0) << e.name;
  }
}

TEST(EffectCatalogue, UnknownNamesAndKeysListTheValidOnes) {
  try {
    find_effect("field_scael");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown effect 'field_scael'"), std::string::npos) << what;
    EXPECT_NE(what.find(effect_names()), std::string::npos) << what;
  }
  try {
    effect_parameter_index(find_effect("floor_slope"), "angel_deg");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("angle_deg, direction_deg"), std::string::npos);
  }
}

TEST(ModelExtensions, EveryEffectMapsBothWays) {
  for (const EffectSpec& e : effect_catalogue()) {
    SCOPED_TRACE(e.name);
    ModelExtensions ext;
    EXPECT_FALSE(extension_active(ext, e.name));
    std::vector<double> typed;
    for (const EffectParameter& p : e.params) typed.push_back(p.example);
    set_extension_values(&ext, e.name, typed);
    const std::vector<double> back = extension_values(ext, e.name);
    ASSERT_EQ(back.size(), typed.size());
    for (size_t i = 0; i < typed.size(); ++i) EXPECT_NEAR(back[i], typed[i], 1e-12);
    EXPECT_TRUE(extension_active(ext, e.name));
    EXPECT_EQ(active_extensions(ext), std::vector<std::string>{e.name});
    EXPECT_DOUBLE_EQ(extension_size(ext, e.name), effect_size(e, typed));
    EXPECT_NO_THROW(ext.validate());
  }
}

}  // namespace
}  // namespace airtwin
