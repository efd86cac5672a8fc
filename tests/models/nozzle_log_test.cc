// The nozzle command log: validation with file:line:column messages, the command in force at a
// time, the round trip, and the recorder's rules for commands sent at one instant.

#include "models/nozzle_log.h"

#include <gtest/gtest.h>

#include "common/errors.h"
#include "common/units.h"

namespace airtwin {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_nozzle_log(text, "n.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(NozzleLog, ReadsCommandsInRadians) {
  const NozzleLog log =
      parse_nozzle_log("# servo log\nt,pan_deg,tilt_deg\n0,90,22.5\n\n1.5,-45,0\r\n", "n.csv");
  ASSERT_EQ(log.commands.size(), 2u);
  EXPECT_EQ(log.commands[1].t_s, 1.5);
  EXPECT_NEAR(log.commands[0].nozzle.pan_rad, kPi / 2, 1e-15);
  EXPECT_NEAR(log.commands[0].nozzle.tilt_rad, kPi / 8, 1e-15);
  EXPECT_NEAR(log.commands[1].nozzle.pan_rad, -kPi / 4, 1e-15);
  EXPECT_EQ(log.where(1), "n.csv:5");
}

TEST(NozzleLog, TheCommandInForceIsTheLastAtOrBeforeTheTime) {
  const NozzleLog log = parse_nozzle_log("t,pan_deg,tilt_deg\n-1,0,10\n0,0,20\n2,0,30\n", "n.csv");
  EXPECT_EQ(log.index_at(-1.0001), -1);
  EXPECT_EQ(log.index_at(-1.0), 0);  // in force from its time on, that instant included
  EXPECT_EQ(log.index_at(-0.5), 0);
  EXPECT_EQ(log.index_at(0.0), 1);
  EXPECT_EQ(log.index_at(1.999), 1);
  EXPECT_EQ(log.index_at(2.0), 2);
  EXPECT_EQ(log.index_at(1e9), 2);
}

TEST(NozzleLog, RoundTripKeepsEverything) {
  const std::string text =
      "t,pan_deg,tilt_deg\n"
      "-0.500000,-90.000000,50.000000\n"
      "0.000000,35.000000,22.500000\n"
      "0.025000,181.250000,0.000000\n";
  const NozzleLog log = parse_nozzle_log(text, "n.csv");
  EXPECT_EQ(nozzle_log_csv(log.commands), text);
}

TEST(NozzleLog, ErrorsNameFileLineColumnAndValue) {
  const std::string h = "t,pan_deg,tilt_deg\n";
  EXPECT_NE(error_of("").find("n.csv: empty file"), std::string::npos);
  EXPECT_NE(error_of(h).find("n.csv: no nozzle command after the header"), std::string::npos);
  EXPECT_NE(error_of("t,pan_deg\n0,0\n").find("missing column 'tilt_deg'"), std::string::npos);
  EXPECT_NE(error_of("t,pan_deg,tilt_deg,pan_actual_deg\n0,0,0,0\n").find("pan_actual_deg"),
            std::string::npos);
  EXPECT_NE(error_of(h + "0,0,0\n1,nan,0\n")
                .find("n.csv:3: column 'pan_deg': expected a finite "
                      "number, got 'nan'"),
            std::string::npos);
  EXPECT_NE(error_of(h + "0,0,abc\n")
                .find("n.csv:2: column 'tilt_deg': expected a finite number, "
                      "got 'abc'"),
            std::string::npos);
  EXPECT_NE(error_of(h + "0,0,90\n")
                .find("n.csv:2: column 'tilt_deg': expected a tilt in [0, 90) "
                      "deg, got 90"),
            std::string::npos);
  EXPECT_NE(error_of(h + "0,0,0\n0.5,0,1\n0.5,0,2\n")
                .find("n.csv:4: column 't': expected a time after line 3's 0.5 s (commands in "
                      "time order, one per instant), got 0.5 again"),
            std::string::npos);
  EXPECT_NE(error_of(h + "1,0,0\n0.5,0,1\n")
                .find("n.csv:3: column 't': expected a time after "
                      "line 2's 1 s"),
            std::string::npos);
  EXPECT_NE(error_of(h + "0,0,0,7\n").find("n.csv:2"), std::string::npos);
}

TEST(NozzleLog, RecorderKeepsTheLastCommandOfAnInstantAndOnlyChanges) {
  const NozzleOrientation a{0.1, 0.2}, b{0.3, 0.4}, c{0.5, 0.6};
  std::vector<NozzleCommand> log;
  record_command(&log, 0.0, a);
  record_command(&log, 0.0, b);  // sent at the same instant: b is in force from it
  record_command(&log, 1.5, b);  // the same command again: no change
  record_command(&log, 3.0, c);
  record_command(&log, 4.5, a);
  ASSERT_EQ(log.size(), 3u);
  EXPECT_EQ(log[0].t_s, 0.0);
  EXPECT_EQ(log[0].nozzle.pan_rad, b.pan_rad);
  EXPECT_EQ(log[1].t_s, 3.0);
  EXPECT_EQ(log[1].nozzle.tilt_rad, c.tilt_rad);
  EXPECT_EQ(log[2].t_s, 4.5);
  // What it writes reads back to the same commands (to the file's 6 decimals).
  const NozzleLog back = parse_nozzle_log(nozzle_log_csv(log), "n.csv");
  ASSERT_EQ(back.commands.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.commands[i].t_s, log[i].t_s);
    EXPECT_NEAR(back.commands[i].nozzle.pan_rad, log[i].nozzle.pan_rad, deg_to_rad(1e-6));
    EXPECT_NEAR(back.commands[i].nozzle.tilt_rad, log[i].nozzle.tilt_rad, deg_to_rad(1e-6));
  }
}

}  // namespace
}  // namespace airtwin
