// serve's recordings left unfinished by a crash: found by their temporary's name, recovered
// under the name they would have had, the temporary removed; one still being written by a live
// process (its lock held) or not readable is left where it is.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/mcap_writer.h"
#include "microcobot/core/staged_file.h"
#include "microcobot/live/recording_recovery.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

TEST(RecordingRecovery, KnowsServesTemporariesByName) {
  EXPECT_EQ(unfinished_recording_stem(".recording-20261205-101010.mcap.Ab12Cd").value_or(""),
            "recording-20261205-101010");
  EXPECT_EQ(unfinished_recording_stem("/x/.recording-20261205-101010-2.mcap.zzzzzz").value_or(""),
            "recording-20261205-101010-2");
  EXPECT_FALSE(unfinished_recording_stem("recording-20261205-101010.mcap"));  // finished
  EXPECT_FALSE(unfinished_recording_stem(".recording-20261205-101010.csv.Ab12Cd"));
  EXPECT_FALSE(unfinished_recording_stem(".notes.mcap.Ab12Cd"));  // not serve's
  EXPECT_FALSE(unfinished_recording_stem(".recording-20261205-101010.mcap.Ab1"));
}

TEST(RecordingRecovery, RecoversWhatACrashLeftAndLeavesWhatIsStillBeingWritten) {
  test::TempDir dir;
  // A recording cut 60 bytes before its end (in its summary): what a crash leaves on disk.
  {
    McapWriter w(dir.path() / "full.mcap");
    const auto ch = w.add_channel(0, "/telemetry", "json");
    for (std::uint64_t i = 0; i < 200; ++i) w.write(ch, i * 10'000'000, 0, "{}");
    w.close();
  }
  const std::string full = test::read_text(dir.path() / "full.mcap");
  fs::remove(dir.path() / "full.mcap");
  test::write_text(dir.path() / ".recording-20261205-101010.mcap.Ab12Cd", full.substr(0, full.size() - 60));
  // A finished recording already has that stem: the recovered one takes the next name.
  test::write_text(dir.path() / "recording-20261205-101010.mcap", full);
  // Not an MCAP file: left, with its error.
  test::write_text(dir.path() / ".recording-20261205-111111.mcap.Zz99Zz", "garbage");
  // Being written by a live writer (this process): left alone.
  StagedFile live(dir.path() / "recording-20261205-121212.mcap");
  live.write("\x89MCAP0\r\n");

  const auto recovered = recover_unfinished_recordings(dir.path());
  ASSERT_EQ(recovered.size(), 2u);
  const auto& ok = recovered[0].error.empty() ? recovered[0] : recovered[1];
  const auto& bad = recovered[0].error.empty() ? recovered[1] : recovered[0];
  EXPECT_EQ(ok.to.filename(), "recording-20261205-101010-2.mcap");
  EXPECT_EQ(ok.messages, 200u);
  EXPECT_NEAR(ok.duration_s, 1.99, 1e-9);
  EXPECT_FALSE(fs::exists(ok.from)) << "the temporary removed once recovered";
  EXPECT_EQ(read_mcap(ok.to).messages.size(), 200u);
  EXPECT_THAT(bad.error, HasSubstr("not an MCAP file"));
  EXPECT_TRUE(fs::exists(bad.from));
  std::size_t temporaries = 0;
  for (const auto& e : fs::directory_iterator(dir.path()))
    temporaries += e.path().filename().string().rfind(".recording-20261205-121212.mcap.", 0) == 0;
  EXPECT_EQ(temporaries, 1u) << "the live writer's file untouched";
  live.discard();
  EXPECT_TRUE(recover_unfinished_recordings(dir.path()).size() == 1u) << "only the unreadable one is left";
}

}  // namespace
}  // namespace mc::live
