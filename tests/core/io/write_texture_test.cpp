// Texture inputs: the generated UV check is a PNG of the asked size; user
// images are embedded only when their header is a real PNG/JPEG.
#include <gtest/gtest.h>

#include "soupuv/errors.h"
#include "soupuv/io/texture.h"

namespace soupuv::io {
namespace {

TEST(WriteTexture, UvCheckIsAPngOfTheAskedSize) {
  Texture t = uv_check_texture(256);
  EXPECT_EQ(t.mime_type, "image/png");
  EXPECT_EQ(t.width, 256u);
  // Our own header check reads the same dimensions back.
  Texture again = texture_from_bytes(t.bytes);
  EXPECT_EQ(again.width, 256u);
  EXPECT_EQ(again.height, 256u);
  EXPECT_THROW(uv_check_texture(300), Error);
}

TEST(WriteTexture, JpegDimensionsFromTheFrameHeader) {
  // SOI, an APP0 segment, then SOF0 with height 48, width 64.
  std::vector<uint8_t> jpeg = {0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x04, 0x00, 0x00,
                               0xFF, 0xC0, 0x00, 0x0B, 0x08, 0x00, 0x30, 0x00, 0x40, 0x01,
                               0x01, 0x11, 0x00, 0xFF, 0xD9};
  Texture t = texture_from_bytes(jpeg);
  EXPECT_EQ(t.mime_type, "image/jpeg");
  EXPECT_EQ(t.width, 64u);
  EXPECT_EQ(t.height, 48u);
  EXPECT_EQ(t.bytes, jpeg);
}

TEST(WriteTexture, GarbageAndTruncatedHeadersAreRefused) {
  std::vector<uint8_t> garbage = {'h', 'e', 'l', 'l', 'o'};
  EXPECT_THROW(texture_from_bytes(garbage), Error);
  Texture png = uv_check_texture(64);
  std::vector<uint8_t> cut(png.bytes.begin(), png.bytes.begin() + 20);
  EXPECT_THROW(texture_from_bytes(cut), Error);
  std::vector<uint8_t> jpeg_lie = {0xFF, 0xD8, 0xFF, 0xE0, 0x40, 0x00, 0x00};  // segment beyond end
  EXPECT_THROW(texture_from_bytes(jpeg_lie), Error);
  std::vector<uint8_t> empty;
  EXPECT_THROW(texture_from_bytes(empty), Error);
}

}  // namespace
}  // namespace soupuv::io
