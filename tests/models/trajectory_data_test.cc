// The trajectory CSV: validation with file:line:column messages, interleaved rows, round trip.

#include "models/trajectory_data.h"

#include <gtest/gtest.h>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

const char* kHeader = "traj,object,t,x,y,pan_deg,tilt_deg\n";

std::string error_of(const std::string& text) {
  try {
    parse_trajectory_csv(text, "d.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TrajectoryData, ReadsInterleavedMultiObjectLogs) {
  const TrajectorySet s = parse_trajectory_csv(std::string(kHeader) +
                                                   "a,tracer,0,0.1,0.2,90,22.5\n"
                                                   "b,cotton,0,0.3,0.4,90,22.5\n"
                                                   "a,tracer,0.025,0.11,0.2,90,22.5\n"
                                                   "b,cotton,0.025,0.31,0.4,45,0\n",
                                               "d.csv");
  ASSERT_EQ(s.trajectories.size(), 2u);
  EXPECT_EQ(s.trajectories[0].id, "a");
  EXPECT_EQ(s.trajectories[1].object, "cotton");
  ASSERT_EQ(s.trajectories[1].samples.size(), 2u);
  EXPECT_NEAR(s.trajectories[1].samples[1].nozzle.pan_rad, deg_to_rad(45), 1e-15);
  EXPECT_EQ(s.trajectories[0].samples[1].p_W, Eigen::Vector2d(0.11, 0.2));
  EXPECT_FALSE(s.has_group);
}

TEST(TrajectoryData, RoundTripKeepsEverything) {
  const std::string text =
      "traj,object,t,x,y,pan_deg,tilt_deg,group\n"
      "7,tracer,0.000000,0.100000,-0.200000,-90.000000,50.000000,left\n"
      "7,tracer,0.025000,0.101000,-0.200000,-90.000000,50.000000,left\n";
  const TrajectorySet s = parse_trajectory_csv(text, "d.csv");
  EXPECT_TRUE(s.has_group);
  EXPECT_EQ(s.trajectories[0].group, "left");
  EXPECT_EQ(trajectory_csv(s), text);
}

TEST(TrajectoryData, MergedFilesKeepTheirTrajectoriesApart) {
  // Two closed-loop logs that both call their tracer t1.
  const std::string a = std::string(kHeader) +
                        "t1,tracer,0,0.1,0.2,90,22.5\n"
                        "t1,tracer,0.025,0.11,0.2,90,22.5\n";
  const std::string b =
      "traj,object,t,x,y,pan_deg,tilt_deg,group\n"
      "t1,tracer,0,-0.3,0.4,10,15,line\n"
      "c,cotton,0,0.5,0.4,10,15,line\n";
  const TrajectorySet one = merge_trajectory_sets({parse_trajectory_csv(a, "a.csv")});
  EXPECT_EQ(trajectory_csv(one), trajectory_csv(parse_trajectory_csv(a, "a.csv")));  // as it was

  const TrajectorySet m =
      merge_trajectory_sets({parse_trajectory_csv(a, "a.csv"), parse_trajectory_csv(b, "b.csv")});
  ASSERT_EQ(m.trajectories.size(), 3u);
  EXPECT_EQ(m.trajectories[0].id, "1:t1");
  EXPECT_EQ(m.trajectories[1].id, "2:t1");
  EXPECT_EQ(m.trajectories[2].id, "2:c");
  EXPECT_EQ(m.trajectories[0].samples.size(), 2u);
  EXPECT_EQ(m.trajectories[1].samples.front().p_W, Eigen::Vector2d(-0.3, 0.4));
  EXPECT_EQ(m.trajectories[2].object, "cotton");
  EXPECT_TRUE(m.has_group);
  EXPECT_EQ(m.trajectories[0].group, "");
  EXPECT_EQ(m.trajectories[1].group, "line");
  // The merged set reads back as one file with the same trajectories.
  const TrajectorySet back = parse_trajectory_csv(trajectory_csv(m), "m.csv");
  ASSERT_EQ(back.trajectories.size(), 3u);
  EXPECT_EQ(back.trajectories[1].id, "2:t1");
}

TEST(TrajectoryData, ErrorsNameFileLineAndColumn) {
  const std::string h = kHeader;
  EXPECT_NE(error_of("").find("d.csv: empty file"), std::string::npos);
  EXPECT_NE(error_of(h).find("no data rows"), std::string::npos);
  EXPECT_NE(
      error_of("traj,object,t,x,pan_deg,tilt_deg\n1,tracer,0,0,0,0\n").find("missing column 'y'"),
      std::string::npos);
  EXPECT_NE(error_of(h + "1,tracer,0,nan,0,0,0\n").find("d.csv:2: column 'x'"), std::string::npos);
  EXPECT_NE(error_of(h + "1,pebble,0,0,0,0,0\n").find("unknown object type 'pebble'"),
            std::string::npos);
  EXPECT_NE(error_of(h + "1,tracer,0,0,0,0,0\n1,tracer,0,0,0,0,0\n").find("d.csv:3: column 't'"),
            std::string::npos);
  EXPECT_NE(error_of(h + "1,tracer,0,0,0,0,0\n1,cotton,1,0,0,0,0\n").find("was 'tracer'"),
            std::string::npos);
  EXPECT_NE(error_of(h + "1,tracer,0,0,0,0,95\n").find("column 'tilt_deg'"), std::string::npos);
  EXPECT_NE(error_of(h + ",tracer,0,0,0,0,0\n").find("empty trajectory id"), std::string::npos);
  EXPECT_NE(error_of(std::string("\x7f"
                                 "ELF\x02\x01\x01\0\0",
                                 9))
                .find("not a text CSV"),
            std::string::npos);
}

}  // namespace
}  // namespace airtwin
