// The MuJoCo runtime wrapper: loading from memory, one-line fatal errors (no "Press Enter"),
// warnings counted instead of printed.

#include "sim/mujoco_runtime.h"

#include <gtest/gtest.h>

#include <string>

#include "common/errors.h"

namespace airtwin {
namespace {

constexpr const char* kBox = R"(
<mujoco>
  <worldbody>
    <geom type="plane" size="1 1 0.1"/>
    <body name="box" pos="0 0 0.1"><freejoint/><geom type="box" size="0.05 0.05 0.05"/></body>
  </worldbody>
</mujoco>)";

TEST(MujocoRuntime, LoadsMjcfFromMemory) {
  ModelPtr m = load_model_from_xml(kBox, "inline box");
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->nbody, 2);
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_BODY, "box"), 0);
  // The box falls and lands: the model is usable.
  DataPtr d = make_data(m.get());
  for (int k = 0; k < 500; ++k) mj_step(m.get(), d.get());
  EXPECT_NEAR(d->qpos[2], 0.05, 0.005);
}

TEST(MujocoRuntime, BadMjcfIsAnInputErrorNamingTheSource) {
  try {
    load_model_from_xml(
        "<mujoco><worldbody><body><geom type=\"nosuch\"/></body></worldbody>"
        "</mujoco>",
        "scenes/broken.xml");
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("scenes/broken.xml"), std::string::npos) << what;
    EXPECT_NE(what.find("MuJoCo cannot load"), std::string::npos) << what;
  }
}

TEST(MujocoRuntimeDeathTest, EngineErrorIsOneLineAndANonZeroExit) {
  // Without the handler MuJoCo would print "Press Enter to exit" and wait on stdin.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  install_mujoco_handlers();
  EXPECT_EXIT(mju_error("stack overflow in test"), testing::ExitedWithCode(kMujocoErrorExitStatus),
              "^airtwin: MuJoCo engine error: stack overflow in test\n$");
}

TEST(MujocoRuntimeDeathTest, HandlersSurviveAModelLoad) {
  // MuJoCo 2.2's compiler swaps the handlers while it runs; they must be ours afterwards.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  load_model_from_xml(kBox, "inline box");
  EXPECT_EXIT(mju_error("after load"), testing::ExitedWithCode(kMujocoErrorExitStatus),
              "MuJoCo engine error: after load");
}

TEST(MujocoRuntime, WarningsAreCountedNotPrinted) {
  ModelPtr m = load_model_from_xml(kBox, "inline box");
  DataPtr d = make_data(m.get());
  take_thread_warnings();
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  mj_warning(d.get(), mjWARN_CNSTRFULL, 7);
  mj_warning(d.get(), mjWARN_CNSTRFULL, 8);
  const std::string err = testing::internal::GetCapturedStderr();
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_EQ(err, "");
  EXPECT_EQ(out, "");
  EXPECT_EQ(d->warning[mjWARN_CNSTRFULL].number, 2);
  const ThreadWarnings w = take_thread_warnings();
  EXPECT_GE(w.count, 1);
  EXPECT_FALSE(w.last_message.empty());
  EXPECT_EQ(take_thread_warnings().count, 0);
}

}  // namespace
}  // namespace airtwin
