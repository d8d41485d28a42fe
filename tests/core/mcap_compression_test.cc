// zstd-compressed MCAP chunks, Metadata and Attachment records: written by
// McapWriter, read back and checked by the strict reader.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/core/mcap_reader.h"
#include "microcobot/core/mcap_writer.h"
#include "microcobot/core/zstd.h"
#include "support/test_support.h"

namespace mc {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace mcap_compression_test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

std::string payload(std::size_t i) {
  return "{\"t_s\":" + std::to_string(0.001 * static_cast<double>(i)) + ",\"x_m\":" + std::to_string(i % 97) +
         ",\"pad\":\"" + std::string(40 + i % 17, 'x') + "\"}";
}

const std::string kConfig = "loop:\n  base_rate_Hz: 10000\n";

// Two channels, 2000 messages in 16 KiB chunks (several), zstd; metadata and an attachment.
void write_fixture(const fs::path& file, bool zstd = true) {
  McapWriter w(file, 16384, McapCompression{zstd, 3});
  const auto s = w.add_schema("test.A", "jsonschema", R"({"type":"object"})");
  const auto a = w.add_channel(s, "/a", "json");
  const auto b = w.add_channel(s, "/b", "json");
  w.add_metadata("microcobot", {{"version", "microcobot 0.1.0"}, {"scene", "pick-place"}});
  w.add_attachment("configuration.yaml", "application/yaml", kConfig, 5, 6);
  for (std::size_t i = 0; i < 2000; ++i) w.write(i % 4 ? a : b, 1'000'000 * i, 1'000'000 * i, payload(i));
  w.add_metadata("late", {});
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

TEST(Zstd, RoundTripsAndRefusesWhatDoesNotExpandAsStated) {
  std::string text;
  for (int i = 0; i < 1000; ++i) text += payload(static_cast<std::size_t>(i));
  std::string packed;
  zstd_compress(text, 3, packed);
  EXPECT_LT(packed.size(), text.size() / 4);
  EXPECT_EQ(zstd_decompress(packed, text.size(), "t"), text);
  EXPECT_THAT([&] { zstd_decompress(packed, text.size() - 1, "t"); },
              ::testing::ThrowsMessage<InvalidInput>(HasSubstr("not the")));
  EXPECT_THAT([&] { zstd_decompress(packed, text.size() + 1, "t"); },
              ::testing::ThrowsMessage<InvalidInput>(HasSubstr("not the")));
  std::string corrupt = packed;
  corrupt[corrupt.size() / 2] ^= 0x5A;
  corrupt[corrupt.size() / 2 + 1] ^= 0x5A;
  EXPECT_THROW(zstd_decompress(corrupt, text.size(), "t"), InvalidInput);
  EXPECT_THAT([&] { zstd_decompress(packed, std::size_t{1} << 40, "t"); },
              ::testing::ThrowsMessage<InvalidInput>(HasSubstr("more than")));
  EXPECT_THROW(zstd_compress(text, 0, packed), InvalidParams);
}

TEST(Mcap, ZstdChunksRoundTripWithTheirIndexesMetadataAndAttachments) {
  test::TempDir dir;
  write_fixture(dir / "z.mcap", true);
  write_fixture(dir / "u.mcap", false);
  const McapContents z = read_mcap(dir / "z.mcap"), u = read_mcap(dir / "u.mcap");
  ASSERT_EQ(z.messages.size(), 2000u);
  ASSERT_EQ(u.messages.size(), 2000u);
  for (std::size_t i = 0; i < z.messages.size(); ++i) {
    EXPECT_EQ(z.messages[i].data, payload(i));
    EXPECT_EQ(z.messages[i].log_time_ns, u.messages[i].log_time_ns);
    EXPECT_EQ(z.messages[i].channel_id, u.messages[i].channel_id);
  }
  ASSERT_GT(z.chunks.size(), 3u);
  ASSERT_EQ(z.chunks.size(), u.chunks.size());
  for (std::size_t c = 0; c < z.chunks.size(); ++c) {
    EXPECT_EQ(z.chunks[c].compression, "zstd");
    EXPECT_LT(z.chunks[c].compressed_size, z.chunks[c].uncompressed_size / 3) << "chunk " << c;
    EXPECT_EQ(z.chunks[c].uncompressed_size, u.chunks[c].uncompressed_size);
    EXPECT_EQ(u.chunks[c].compression, "");
    EXPECT_EQ(u.chunks[c].compressed_size, u.chunks[c].uncompressed_size);
  }
  EXPECT_LT(fs::file_size(dir / "z.mcap"), fs::file_size(dir / "u.mcap") / 3);
  ASSERT_EQ(z.metadata.size(), 2u);
  ASSERT_NE(z.find_metadata("microcobot"), nullptr);
  EXPECT_EQ(*z.find_metadata("microcobot")->find("version"), "microcobot 0.1.0");
  EXPECT_EQ(z.find_metadata("microcobot")->find("nothing"), nullptr);
  EXPECT_TRUE(z.find_metadata("late")->entries.empty());
  ASSERT_EQ(z.attachments.size(), 1u);
  EXPECT_EQ(z.attachments[0].name, "configuration.yaml");
  EXPECT_EQ(z.attachments[0].media_type, "application/yaml");
  EXPECT_EQ(z.attachments[0].data, kConfig);
  EXPECT_EQ(z.attachments[0].log_time_ns, 5u);
  EXPECT_EQ(z.attachments[0].create_time_ns, 6u);
  EXPECT_EQ(z.statistics.metadata_count, 2u);
  EXPECT_EQ(z.statistics.attachment_count, 1u);
}

TEST(Mcap, AZstdChunkIsCheckedAfterDecompressionByItsCrc) {
  test::TempDir dir;
  const auto file = dir / "crc.mcap";
  write_fixture(file);
  std::string bytes = test::read_text(file);
  // The Chunk's fields: ..., uncompressed_crc (u32), compression (u32 length 4, "zstd"), records.
  const auto at = bytes.find(std::string("\x04\0\0\0zstd", 8));
  ASSERT_NE(at, std::string::npos);
  bytes[at - 4] ^= 0x01;  // the stored CRC of the uncompressed records
  test::write_text(file, bytes);
  const std::string err = thrown_by_read(file);
  EXPECT_THAT(err, HasSubstr("Chunk CRC mismatch"));
  EXPECT_THAT(err, HasSubstr("zstd chunk at byte"));
  EXPECT_THAT(err, Not(HasSubstr("\n")));
}

TEST(Mcap, CorruptZstdDataIsANamedError) {
  test::TempDir dir;
  const auto file = dir / "data.mcap";
  write_fixture(file);
  std::string bytes = test::read_text(file);
  const auto at = bytes.find(std::string("\x04\0\0\0zstd", 8));
  ASSERT_NE(at, std::string::npos);
  // Past the records' u64 length and the frame header: the compressed blocks.
  for (std::size_t k = 0; k < 8; ++k) bytes[at + 8 + 8 + 40 + k] ^= 0x5A;
  test::write_text(file, bytes);
  const std::string err = thrown_by_read(file);
  EXPECT_THAT(err, HasSubstr(file.string()));
  EXPECT_THAT(err, HasSubstr("zstd"));
  EXPECT_THAT(err, Not(HasSubstr("\n")));
}

TEST(Mcap, ACorruptAttachmentIsDetectedByItsCrc) {
  test::TempDir dir;
  const auto file = dir / "att.mcap";
  write_fixture(file);
  std::string bytes = test::read_text(file);
  const auto at = bytes.find("base_rate_Hz");
  ASSERT_NE(at, std::string::npos);
  bytes[at] = 'B';
  test::write_text(file, bytes);
  EXPECT_THAT(thrown_by_read(file), HasSubstr("Attachment 'configuration.yaml' CRC mismatch"));
}

TEST(Mcap, ABadZstdLevelIsRefusedAndLeavesNothing) {
  test::TempDir dir;
  EXPECT_THROW(McapWriter(dir / "l.mcap", 4096, McapCompression{true, 42}), InvalidParams);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
}  // namespace mcap_compression_test
}  // namespace mc
