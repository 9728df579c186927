#include "devsurf/server/SurfaceThumbnail.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <algorithm>
#include <map>
#include <vector>
#include <stdexcept>
#include <string>

namespace devsurf::server {
namespace {

/// One planar quad: a w × h rectangle in the plane z = 0.
io::QuadMesh rectangle(double w, double h) {
  io::QuadMesh m;
  m.vertices.resize(4, 3);
  m.vertices << 0, 0, 0, w, 0, 0, w, h, 0, 0, h, 0;
  m.quads.resize(1, 4);
  m.quads << 0, 1, 2, 3;
  return m;
}

double opaqueFraction(const ThumbnailImage& image) {
  std::size_t opaque = 0;
  for (std::size_t k = 3; k < image.rgba.size(); k += 4) opaque += image.rgba[k] == 255;
  return static_cast<double>(opaque) / (image.width * image.height);
}

std::uint8_t alphaAt(const ThumbnailImage& image, int x, int y) {
  return image.rgba[(static_cast<std::size_t>(y) * image.width + x) * 4 + 3];
}

TEST(SurfaceThumbnail, APlaneIsSeenFromItsFaceFillingThePictureUpToTheMargin) {
  ThumbnailOptions options;
  const ThumbnailImage image = renderSurfaceThumbnail(rectangle(2.0, 1.0), options);
  ASSERT_EQ(image.width, 320);
  ASSERT_EQ(image.height, 240);
  ASSERT_EQ(image.rgba.size(), 320u * 240u * 4u);
  // The view is tilted from the plane's normal, so the rectangle appears as a parallelogram
  // that spans the picture's width (less the margins) in x.
  int left = image.width, right = -1;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (alphaAt(image, x, y) > 0) {
        left = std::min(left, x);
        right = std::max(right, x);
      }
  EXPECT_NEAR(left, 0.06 * 240, 1.5);
  EXPECT_NEAR(image.width - 1 - right, 0.06 * 240, 1.5);
  EXPECT_EQ(alphaAt(image, 0, 0), 0) << "the background is transparent";
  EXPECT_EQ(alphaAt(image, image.width / 2, image.height / 2), 255) << "the middle is the surface";
  const double fraction = opaqueFraction(image);
  EXPECT_GT(fraction, 0.3);
  EXPECT_LT(fraction, 0.9);
  // One plane, one shade: every opaque pixel has the same colour.
  const std::size_t mid = (static_cast<std::size_t>(image.height / 2) * image.width + image.width / 2) * 4;
  for (std::size_t k = 0; k < image.rgba.size(); k += 4)
    if (image.rgba[k + 3] == 255)
      ASSERT_EQ(image.rgba[k] + 256 * image.rgba[k + 1] + 65536 * image.rgba[k + 2],
                image.rgba[mid] + 256 * image.rgba[mid + 1] + 65536 * image.rgba[mid + 2]);
}

TEST(SurfaceThumbnail, AFoldedSheetShowsItsTwoFacesInTwoShades) {
  // Two unit squares meeting at a right angle along the y axis.
  io::QuadMesh m;
  m.vertices.resize(6, 3);
  m.vertices << -1, 0, 0, 0, 0, 0, 0, 1, 0, -1, 1, 0, 0, 0, 1, 0, 1, 1;
  m.quads.resize(2, 4);
  m.quads << 0, 1, 2, 3, 1, 4, 5, 2;
  const ThumbnailImage image = renderSurfaceThumbnail(m);
  std::map<int, int> pixelsOfColour;
  int opaque = 0;
  for (std::size_t k = 0; k < image.rgba.size(); k += 4)
    if (image.rgba[k + 3] == 255) {
      ++pixelsOfColour[image.rgba[k] + 256 * image.rgba[k + 1] + 65536 * image.rgba[k + 2]];
      ++opaque;
    }
  std::vector<int> counts;
  for (const auto& [colour, n] : pixelsOfColour) counts.push_back(n);
  std::sort(counts.rbegin(), counts.rend());
  ASSERT_GE(counts.size(), 2u);
  EXPECT_GT(counts[1], opaque / 5) << "both faces are in sight";
  EXPECT_GT(counts[0] + counts[1], 0.97 * opaque) << "in two shades (the rest: pixels on the fold, mixed)";
}

TEST(SurfaceThumbnail, ManyLargeTrianglesOverEachOtherDrawWithFewerSamplesOrAreRefused) {
  auto stacked = [](int copies) {
    io::QuadMesh m;
    m.vertices.resize(4 * copies, 3);
    m.quads.resize(copies, 4);
    for (int k = 0; k < copies; ++k) {
      m.vertices.block(4 * k, 0, 4, 3) << 0, 0, 1e-6 * k, 1, 0, 1e-6 * k, 1, 1, 1e-6 * k, 0, 1, 1e-6 * k;
      m.quads.row(k) << 4 * k, 4 * k + 1, 4 * k + 2, 4 * k + 3;
    }
    return m;
  };
  const ThumbnailImage some = renderSurfaceThumbnail(stacked(200));
  EXPECT_GT(opaqueFraction(some), 0.2) << "drawn, one sample per pixel";
  EXPECT_THROW(renderSurfaceThumbnail(stacked(3000)), std::invalid_argument);
}

TEST(SurfaceThumbnail, IsAPngOfTheAskedSize) {
  ThumbnailOptions options;
  options.width = 64;
  options.height = 48;
  const std::string png = surfaceThumbnailPng(rectangle(1.0, 1.0), options);
  ASSERT_GT(png.size(), 33u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  auto be32 = [&png](std::size_t at) {
    return (static_cast<unsigned>(static_cast<unsigned char>(png[at])) << 24) |
           (static_cast<unsigned>(static_cast<unsigned char>(png[at + 1])) << 16) |
           (static_cast<unsigned>(static_cast<unsigned char>(png[at + 2])) << 8) |
           static_cast<unsigned>(static_cast<unsigned char>(png[at + 3]));
  };
  EXPECT_EQ(be32(16), 64u);
  EXPECT_EQ(be32(20), 48u);
  EXPECT_EQ(png[24], 8) << "8 bits";
  EXPECT_EQ(png[25], 6) << "RGBA";
  EXPECT_EQ(png.substr(png.size() - 8, 4), "IEND");
}

TEST(SurfaceThumbnail, BadOptionsAndEmptySurfacesAreRefused) {
  ThumbnailOptions options;
  options.width = 8;
  EXPECT_THROW(renderSurfaceThumbnail(rectangle(1, 1), options), std::invalid_argument);
  options = {};
  options.supersampling = 9;
  EXPECT_THROW(renderSurfaceThumbnail(rectangle(1, 1), options), std::invalid_argument);
  EXPECT_THROW(renderSurfaceThumbnail(io::QuadMesh{}), std::invalid_argument);
  io::QuadMesh flat = rectangle(1, 1);
  flat.vertices.col(1).setZero();  // every triangle has zero area
  EXPECT_THROW(renderSurfaceThumbnail(flat), std::invalid_argument);
  ThumbnailImage wrong;
  wrong.width = 4;
  wrong.height = 4;
  EXPECT_THROW(pngBytes(wrong), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::server
