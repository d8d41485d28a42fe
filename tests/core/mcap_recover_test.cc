// Recovering MCAP files a writer never closed: cut anywhere, the whole records before the cut are
// kept and written again as an indexed file the strict reader accepts; a chunk whose CRC fails
// ends what is kept; a writer with a chunk span leaves every closed chunk on disk while it runs.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/mcap_recover.h"
#include "microcobot/core/mcap_writer.h"
#include "support/test_support.h"

namespace mc {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string bytes_of(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& f, std::string_view b) {
  std::ofstream out(f, std::ios::binary);
  out.write(b.data(), static_cast<std::streamsize>(b.size()));
}

// Two channels, 100 messages a second of log time for 5 s, a chunk closed every second.
constexpr std::uint64_t kSecond = 1'000'000'000;
void write_recording(const fs::path& file, bool zstd) {
  McapWriter w(file, std::size_t{1} << 20, McapCompression{zstd, 1});
  w.set_chunk_max_span_ns(kSecond);
  const auto s = w.add_schema("test.T", "jsonschema", R"({"type":"object"})");
  const auto a = w.add_channel(s, "/telemetry", "json");
  const auto b = w.add_channel(0, "/events", "json", {{"k", "v"}});
  w.add_metadata("version", {{"program", "microcobot test"}});
  for (std::uint64_t i = 0; i < 500; ++i)
    w.write(i % 10 == 0 ? b : a, i * kSecond / 100, i * kSecond / 100, "{\"i\":" + std::to_string(i) + "}");
  w.close();
}

TEST(McapRecover, AClosedFileIsRecoveredWhole) {
  test::TempDir dir;
  write_recording(dir.path() / "whole.mcap", true);
  const McapRecovery r = recover_mcap(dir.path() / "whole.mcap", dir.path() / "again.mcap");
  EXPECT_TRUE(r.salvage.complete) << r.salvage.stopped;
  EXPECT_EQ(r.messages, 500u);
  EXPECT_NEAR(r.duration_s, 4.99, 1e-9);
  const McapContents c = read_mcap(dir.path() / "again.mcap");
  ASSERT_EQ(c.messages.size(), 500u);
  EXPECT_EQ(c.messages[137].data, "{\"i\":137}");
  ASSERT_EQ(c.channels.size(), 2u);
  EXPECT_EQ(c.channels[1].topic, "/events");
  EXPECT_EQ(c.channels[1].metadata.at(0).second, "v");
  ASSERT_NE(c.find_metadata("version"), nullptr);
  const McapMetadata* rec = c.find_metadata("recovery");
  ASSERT_NE(rec, nullptr);
  EXPECT_EQ(*rec->find("from"), "whole.mcap");
  EXPECT_EQ(*rec->find("complete"), "true");
  EXPECT_EQ(c.chunks.at(0).compression, "zstd");
}

TEST(McapRecover, ACutAnywhereKeepsEveryWholeChunkBeforeIt) {
  for (const bool zstd : {false, true}) {
    test::TempDir dir;
    write_recording(dir.path() / "whole.mcap", zstd);
    const std::string whole = bytes_of(dir.path() / "whole.mcap");
    const McapContents original = read_mcap(dir.path() / "whole.mcap");
    ASSERT_GE(original.chunk_count, 5u);
    // Cuts from just past the Header to the end, every few hundred bytes.
    std::size_t last_kept = 0;
    for (std::size_t cut = 40; cut < whole.size(); cut += 97) {
      const fs::path part = dir.path() / "cut.mcap";
      write_bytes(part, std::string_view(whole).substr(0, cut));
      fs::remove(dir.path() / "out.mcap");
      const McapRecovery r = recover_mcap(part, dir.path() / "out.mcap");
      EXPECT_LE(r.salvage.whole_bytes, cut);
      const McapContents c = read_mcap(dir.path() / "out.mcap");  // a file the strict reader accepts
      // What is kept is a prefix of the original, in whole chunks of 100 messages.
      ASSERT_LE(c.messages.size(), original.messages.size());
      EXPECT_EQ(c.messages.size() % 100, 0u) << "cut at byte " << cut;
      for (std::size_t i = 0; i < c.messages.size(); i += 37)
        EXPECT_EQ(c.messages[i].data, original.messages[i].data);
      EXPECT_GE(c.messages.size(), last_kept) << "a later cut never keeps less";
      last_kept = c.messages.size();
      if (!r.salvage.complete) {
        EXPECT_FALSE(r.salvage.stopped.empty());
      }
    }
    EXPECT_EQ(last_kept, 500u) << "a cut in the summary keeps every message";
  }
}

TEST(McapRecover, AChunkThatFailsItsCrcEndsWhatIsKept) {
  test::TempDir dir;
  write_recording(dir.path() / "whole.mcap", false);
  std::string b = bytes_of(dir.path() / "whole.mcap");
  // A byte of the third chunk's records changed (uncompressed: its messages' text).
  const auto third = b.find("{\"i\":250}");
  ASSERT_NE(third, std::string::npos);
  b[third + 5] = '9';
  write_bytes(dir.path() / "bad.mcap", b);
  const McapRecovery r = recover_mcap(dir.path() / "bad.mcap", dir.path() / "out.mcap");
  EXPECT_FALSE(r.salvage.complete);
  EXPECT_THAT(r.salvage.stopped, HasSubstr("CRC"));
  EXPECT_EQ(r.messages, 200u) << "the two chunks before the corrupt one";
}

TEST(McapRecover, RefusesWhatIsNotMcapInOneLine) {
  test::TempDir dir;
  write_bytes(dir.path() / "text.mcap", "hello, this is not a recording");
  try {
    recover_mcap(dir.path() / "text.mcap", dir.path() / "out.mcap");
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("text.mcap"));
    EXPECT_THAT(e.what(), HasSubstr("not an MCAP file"));
  }
  EXPECT_FALSE(fs::exists(dir.path() / "out.mcap")) << "nothing written";
  EXPECT_THROW(recover_mcap(dir.path() / "missing.mcap", dir.path() / "out.mcap"), InvalidInput);
}

TEST(McapRecover, AWriterWithAChunkSpanLeavesItsClosedChunksOnDiskWhileItRuns) {
  // What a crash would leave: the temporary file as the writer has written it so far.
  test::TempDir dir;
  McapWriter w(dir.path() / "live.mcap", std::size_t{1} << 20, McapCompression{true, 1});
  w.set_chunk_max_span_ns(kSecond);
  const auto ch = w.add_channel(0, "/telemetry", "json");
  for (std::uint64_t i = 0; i <= 350; ++i) w.write(ch, i * kSecond / 100, 0, "{}");  // 3.5 s
  EXPECT_EQ(w.chunk_count(), 3u) << "one chunk per second of messages";
  fs::path tmp;
  for (const auto& e : fs::directory_iterator(dir.path())) tmp = e.path();
  ASSERT_THAT(tmp.filename().string(), HasSubstr(".live.mcap."));
  const McapSalvage s = salvage_mcap(bytes_of(tmp), tmp.string());
  EXPECT_FALSE(s.complete);
  EXPECT_EQ(s.contents.messages.size(), 300u) << "the three closed chunks, written through";
  EXPECT_EQ(s.whole_bytes, s.file_bytes) << "nothing half-written between chunks";
}

}  // namespace
}  // namespace mc
