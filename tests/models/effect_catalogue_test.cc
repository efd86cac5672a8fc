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
    if (!e.per_type) continue;
    // One type's own: that type feels it, another does not, the shared one is untouched.
    const std::string own = std::string(e.name) + "@cotton";
    ModelExtensions typed_ext;
    set_extension_values(&typed_ext, own, typed);
    EXPECT_FALSE(extension_active(typed_ext, e.name));
    EXPECT_TRUE(extension_active(typed_ext, own));
    EXPECT_EQ(active_extensions(typed_ext), std::vector<std::string>{own});
    EXPECT_EQ(extension_values(typed_ext.for_type("cotton"), e.name), back);
    EXPECT_FALSE(extension_active(typed_ext.for_type("tracer"), e.name));
    EXPECT_TRUE(typed_ext.for_type("cotton").object_by_type.empty());
    // Switched off again: no entry is left (one model, one written form).
    std::vector<double> off;
    for (const EffectParameter& p : e.params) off.push_back(p.off);
    set_extension_values(&typed_ext, own, off);
    EXPECT_TRUE(typed_ext.object_by_type.empty());
  }
}

// The objects' own effects per type, and the rig's only shared: which effect is which is the
// catalogue's (an effect of the air or the nozzle acts on every object alike).
TEST(ModelExtensions, AnObjectsOwnEffectMayDifferPerType) {
  std::vector<std::string> per_type;
  for (const EffectSpec& e : effect_catalogue()) {
    if (e.per_type) per_type.push_back(e.name);
  }
  EXPECT_EQ(per_type, (std::vector<std::string>{"quadratic_drag", "air_lift", "linearised_drag"}));
  ModelExtensions ext;
  set_extension_values(&ext, "linearised_drag", {0.3});
  set_extension_values(&ext, "linearised_drag@tracer", {0.5});
  set_extension_values(&ext, "air_lift@cotton", {0.02});
  EXPECT_EQ(active_extensions(ext), (std::vector<std::string>{"air_lift@cotton", "linearised_drag",
                                                              "linearised_drag@tracer"}));
  // A type's own replaces the shared one for it; an effect it does not have stays shared.
  EXPECT_EQ(ext.object_for("tracer").drag_intercept_share, 0.5);
  EXPECT_EQ(ext.object_for("cotton").drag_intercept_share, 0.3);
  EXPECT_EQ(ext.object_for("cotton").lift_s2_per_m2, 0.02);
  EXPECT_EQ(ext.object_for("tracer").lift_s2_per_m2, 0.0);
  EXPECT_EQ(ext.object_for("glass").drag_intercept_share, 0.3);
  for (const char* bad : {"field_scale@tracer", "linearised_drag@", "linearised_drag@a b"}) {
    EXPECT_THROW(set_extension_values(&ext, bad, {1.0}), InputError) << bad;
  }
  try {
    set_extension_values(&ext, "linearised_drag@tracer", {0.99});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("linearised_drag.intercept_share"), std::string::npos)
        << e.what();
  }
  ext.object_by_type["tracer"].drag_intercept_share = 2.0;
  try {
    ext.validate();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("linearised_drag@tracer"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace airtwin
