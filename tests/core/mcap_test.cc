#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/mcap_writer.h"
#include "support/test_support.h"

namespace mc {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

std::size_t entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
}

// The message `i` of the fixture below: channel 1 + i % 3, time 1 ms * i, a payload that
// names them (and is long enough for several 4 KiB chunks).
std::string payload(std::size_t i) {
  return "{\"i\":" + std::to_string(i) + ",\"pad\":\"" + std::string(40 + i % 17, 'x') + "\"}";
}

// Two schemas, three channels (one without schema), 600 messages in 4 KiB chunks.
void write_fixture(const fs::path& file, std::size_t messages = 600) {
  McapWriter w(file, 4096);
  const auto s1 = w.add_schema("test.A", "jsonschema", R"({"type":"object"})");
  const auto s2 = w.add_schema("test.B", "jsonschema", R"({"type":"object","title":"B"})");
  const auto a = w.add_channel(s1, "/a", "json", {{"k", "v"}, {"rate_hz", "1000"}});
  const auto b = w.add_channel(s2, "/b", "json");
  const auto c = w.add_channel(0, "/c", "json");
  const std::uint16_t ids[] = {a, b, c};
  for (std::size_t i = 0; i < messages; ++i) {
    w.write(ids[i % 3], 1'000'000 * i, 1'000'000 * i + 7, payload(i));
  }
  w.close();
}

std::string thrown_by_read(const fs::path& file) {
  try {
    read_mcap(file);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Mcap, Crc32IsZlibs) {
  EXPECT_EQ(crc32("123456789"), 0xCBF43926u);  // the standard check value of CRC-32/ISO-HDLC
  EXPECT_EQ(crc32(""), 0u);
  EXPECT_EQ(crc32("56789", crc32("1234")), crc32("123456789"));  // chains like zlib
}

TEST(Mcap, RoundTripWithSeveralChannelsAndChunks) {
  test::TempDir dir;
  const auto file = dir / "r.mcap";
  write_fixture(file);
  const std::string bytes = test::read_text(file);
  EXPECT_EQ(bytes.substr(0, 8), std::string(kMcapMagic));
  EXPECT_EQ(bytes.substr(bytes.size() - 8), std::string(kMcapMagic));

  const McapContents m = read_mcap(file);
  EXPECT_EQ(m.profile, "");
  EXPECT_EQ(m.library, "microcobot");
  ASSERT_EQ(m.schemas.size(), 2u);
  EXPECT_EQ(m.schemas[0].id, 1u);
  EXPECT_EQ(m.schemas[1].id, 2u);
  EXPECT_EQ(m.schemas[1].name, "test.B");
  EXPECT_EQ(m.schemas[1].encoding, "jsonschema");
  EXPECT_EQ(m.schemas[1].data, R"({"type":"object","title":"B"})");
  ASSERT_EQ(m.channels.size(), 3u);
  EXPECT_EQ(m.channels[0].id, 1u);
  EXPECT_EQ(m.channels[0].schema_id, 1u);
  EXPECT_EQ(m.channels[0].topic, "/a");
  EXPECT_EQ(m.channels[0].message_encoding, "json");
  EXPECT_EQ(m.channels[0].metadata,
            (std::vector<std::pair<std::string, std::string>>{{"k", "v"}, {"rate_hz", "1000"}}));
  EXPECT_EQ(m.channels[1].schema_id, 2u);
  EXPECT_EQ(m.channels[2].id, 3u);
  EXPECT_EQ(m.channels[2].schema_id, 0u);

  ASSERT_EQ(m.messages.size(), 600u);
  std::vector<std::uint32_t> sequence(4, 0);
  for (std::size_t i = 0; i < m.messages.size(); ++i) {
    const auto& msg = m.messages[i];
    EXPECT_EQ(msg.channel_id, 1 + i % 3);
    EXPECT_EQ(msg.log_time_ns, 1'000'000 * i);
    EXPECT_EQ(msg.publish_time_ns, 1'000'000 * i + 7);
    EXPECT_EQ(msg.sequence, sequence[msg.channel_id]++);
    EXPECT_EQ(msg.data, payload(i));
  }
  EXPECT_GT(m.chunk_count, 3u);  // 600 * ~80 B in 4 KiB chunks

  ASSERT_TRUE(m.has_summary);
  ASSERT_TRUE(m.has_statistics);
  EXPECT_EQ(m.statistics.message_count, 600u);
  EXPECT_EQ(m.statistics.schema_count, 2u);
  EXPECT_EQ(m.statistics.channel_count, 3u);
  EXPECT_EQ(m.statistics.chunk_count, m.chunk_count);
  EXPECT_EQ(m.statistics.attachment_count, 0u);
  EXPECT_EQ(m.statistics.metadata_count, 0u);
  EXPECT_EQ(m.statistics.message_start_time_ns, 0u);
  EXPECT_EQ(m.statistics.message_end_time_ns, 599'000'000u);
  EXPECT_EQ(m.statistics.channel_message_counts,
            (std::map<std::uint16_t, std::uint64_t>{{1, 200}, {2, 200}, {3, 200}}));
  EXPECT_EQ(entries(dir.path()), 1u);  // no temporary file left
}

TEST(Mcap, OneChunkPerMebibyteByDefault) {
  test::TempDir dir;
  McapWriter w(dir / "big.mcap");
  const auto ch = w.add_channel(w.add_schema("s", "jsonschema", "{}"), "/t", "json");
  const std::string p(1000, 'y');
  for (std::uint64_t i = 0; i < 2500; ++i) w.write(ch, i, i, p);  // ~2.5 MB
  w.close();
  EXPECT_EQ(w.chunk_count(), 3u);
  EXPECT_EQ(read_mcap(dir / "big.mcap").chunk_count, 3u);
}

// A long recording's one growing part, the summary's chunk index, takes what its records take:
// no allocation and no vector per chunk. 20 000 chunks of eight channels (a 0.5 s chunk span:
// 2.8 hours) hold 153 bytes of ChunkIndex record each, plus at most one block reserved ahead.
TEST(Mcap, TheChunkIndexHoldsItsRecordsBytesAndNoMore) {
  test::TempDir dir;
  constexpr std::size_t kChunks = 20'000, kChannels = 8;
  // Eight messages of 131 bytes of records (9 prefix, 22 header, 100 payload) close a 1000-byte chunk.
  McapWriter w(dir / "long.mcap", 1000);
  const auto s = w.add_schema("s", "jsonschema", "{}");
  std::vector<std::uint16_t> ch;
  for (std::size_t c = 0; c < kChannels; ++c)
    ch.push_back(w.add_channel(s, "/c" + std::to_string(c), "json"));
  const std::string p(100, 'z');
  for (std::uint64_t k = 0; k < kChunks; ++k)
    for (std::size_t c = 0; c < kChannels; ++c) w.write(ch[c], k * kChannels + c, 0, p);
  EXPECT_EQ(w.chunk_count(), kChunks);
  // 9 prefix + start, end, offset, length (32) + the offsets map (4 + 8 x 10) + index length (8)
  // + compression "" (4) + two sizes (16).
  constexpr std::size_t kRecord = 9 + 32 + 4 + kChannels * 10 + 8 + 4 + 16;
  EXPECT_LE(w.chunk_index_bytes(), kChunks * kRecord + (std::size_t{64} << 10) + 4096);
  EXPECT_GE(w.chunk_index_bytes(), kChunks * kRecord);
  w.close();
  const McapContents m = read_mcap(dir / "long.mcap");  // checks each ChunkIndex against its chunk
  EXPECT_EQ(m.chunk_count, kChunks);
  EXPECT_EQ(m.messages.size(), kChunks * kChannels);
}

TEST(Mcap, AFileWithoutMessagesIsValid) {
  test::TempDir dir;
  McapWriter w(dir / "e.mcap");
  w.add_channel(w.add_schema("s", "jsonschema", "{}"), "/t", "json");
  w.close();
  const auto m = read_mcap(dir / "e.mcap");
  EXPECT_TRUE(m.messages.empty());
  EXPECT_EQ(m.chunk_count, 0u);
  EXPECT_EQ(m.statistics.message_count, 0u);
  EXPECT_EQ(m.statistics.channel_count, 1u);
}

TEST(Mcap, SpanPayloadsAreWrittenAsIs) {
  test::TempDir dir;
  McapWriter w(dir / "b.mcap");
  const auto ch = w.add_channel(0, "/raw", "cbor");
  const std::byte raw[] = {std::byte{0}, std::byte{0xFF}, std::byte{0x89}};
  w.write(ch, 5, 6, std::span<const std::byte>(raw));
  w.close();
  const auto m = read_mcap(dir / "b.mcap");
  ASSERT_EQ(m.messages.size(), 1u);
  EXPECT_EQ(m.messages[0].data, std::string("\0\xFF\x89", 3));
}

TEST(Mcap, UnknownIdsAreRefused) {
  test::TempDir dir;
  McapWriter w(dir / "u.mcap");
  EXPECT_THROW(w.add_channel(3, "/t", "json"), InvalidInput);
  EXPECT_THROW(w.write(1, 0, 0, "{}"), InvalidInput);
  const auto ch = w.add_channel(0, "/t", "json");
  EXPECT_THROW(w.write(static_cast<std::uint16_t>(ch + 1), 0, 0, "{}"), InvalidInput);
}

TEST(Mcap, AnUnclosedWriterLeavesNothing) {
  test::TempDir dir;
  {
    McapWriter w(dir / "cut.mcap", 4096);
    const auto ch = w.add_channel(0, "/t", "json");
    for (std::uint64_t i = 0; i < 1000; ++i) w.write(ch, i, i, payload(i));
  }  // destroyed without close(): a cut run
  EXPECT_FALSE(fs::exists(dir / "cut.mcap"));
  EXPECT_EQ(entries(dir.path()), 0u);
}

TEST(Mcap, AMissingDirectoryIsANamedError) {
  test::TempDir dir;
  try {
    McapWriter w(dir / "no" / "such" / "x.mcap");
    FAIL() << "no error";
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.mcap"));
  }
}

TEST(Mcap, ACorruptChunkIsDetectedByItsCrc) {
  test::TempDir dir;
  const auto file = dir / "c.mcap";
  write_fixture(file);
  std::string bytes = test::read_text(file);
  const auto at = bytes.find(payload(123));
  ASSERT_NE(at, std::string::npos);
  bytes[at + 10] = 'Z';
  test::write_text(file, bytes);
  const std::string err = thrown_by_read(file);
  EXPECT_THAT(err, HasSubstr(file.string()));
  EXPECT_THAT(err, HasSubstr("Chunk CRC mismatch"));
  EXPECT_THAT(err, HasSubstr("byte "));
  EXPECT_THAT(err, Not(HasSubstr("\n")));
}

TEST(Mcap, ACorruptHeaderIsDetectedByTheDataSectionCrc) {
  test::TempDir dir;
  const auto file = dir / "d.mcap";
  write_fixture(file);
  std::string bytes = test::read_text(file);
  const auto at = bytes.find("microcobot");
  ASSERT_LT(at, 40u);
  bytes[at] = 'M';
  test::write_text(file, bytes);
  EXPECT_THAT(thrown_by_read(file), HasSubstr("data section CRC mismatch"));
}

TEST(Mcap, ACorruptSummaryIsDetectedByItsCrc) {
  test::TempDir dir;
  const auto file = dir / "s.mcap";
  write_fixture(file);
  std::string bytes = test::read_text(file);
  const auto at = bytes.rfind("test.B");  // the summary's copy of the schema
  ASSERT_GT(at, bytes.size() / 2);
  bytes[at] = 'b';
  test::write_text(file, bytes);
  EXPECT_THAT(thrown_by_read(file), HasSubstr("summary CRC mismatch"));
}

TEST(Mcap, ATruncatedFileIsRejectedInOneLine) {
  test::TempDir dir;
  const auto file = dir / "t.mcap";
  write_fixture(file);
  const std::string bytes = test::read_text(file);
  for (const std::size_t keep : {bytes.size() - 1, bytes.size() / 2, std::size_t{20}, std::size_t{0}}) {
    test::write_text(file, bytes.substr(0, keep));
    const std::string err = thrown_by_read(file);
    EXPECT_THAT(err, HasSubstr(file.string() + ": byte ")) << keep;
    EXPECT_THAT(err, Not(HasSubstr("\n"))) << keep;
    EXPECT_TRUE(err.find("truncated") != std::string::npos || err.find("closing magic") != std::string::npos)
        << err;
  }
}

TEST(Mcap, InconsistentIndexesAreRejected) {
  // A wrong Statistics count, with the summary CRC recomputed so that only the count is wrong.
  test::TempDir dir;
  const auto file = dir / "i.mcap";
  write_fixture(file, 30);
  std::string bytes = test::read_text(file);
  const std::uint64_t footer = bytes.size() - 8 - 29;
  std::uint64_t summary_start = 0;
  for (int i = 0; i < 8; ++i) {
    summary_start |= std::uint64_t{static_cast<unsigned char>(bytes[footer + 9 + i])} << (8 * i);
  }
  std::uint64_t stats = summary_start;  // walk the summary's records to the Statistics record
  while (stats < footer && bytes[stats] != '\x0B') {
    std::uint64_t len = 0;
    for (int i = 0; i < 8; ++i)
      len |= std::uint64_t{static_cast<unsigned char>(bytes[stats + 1 + i])} << (8 * i);
    stats += 9 + len;
  }
  ASSERT_LT(stats, footer);
  bytes[stats + 9] = 31;  // message_count's low byte: 30 -> 31
  const std::uint32_t crc = crc32(std::string_view(bytes).substr(summary_start, footer + 25 - summary_start));
  for (int i = 0; i < 4; ++i) bytes[footer + 25 + i] = static_cast<char>((crc >> (8 * i)) & 0xFF);
  test::write_text(file, bytes);
  EXPECT_THAT(thrown_by_read(file), HasSubstr("Statistics message_count is 31, the data has 30"));
}

TEST(Mcap, NotAnMcapFile) {
  test::TempDir dir;
  test::write_text(dir / "n.mcap", std::string(100, 'a'));
  EXPECT_THAT(thrown_by_read(dir / "n.mcap"), HasSubstr("byte 0: not an MCAP file"));
}

}  // namespace
}  // namespace mc
