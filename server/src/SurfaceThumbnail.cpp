// Thumbnails of sampled surfaces for the start page (issue 16 item 6): a z-buffered, flat-shaded
// orthographic picture written as PNG through libpng.
#include "devsurf/server/SurfaceThumbnail.h"

#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

namespace devsurf::server {
namespace {

/// libpng's output callback: appends to the std::string behind the io pointer.
void appendToString(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::string*>(png_get_io_ptr(png));
  out->append(reinterpret_cast<const char*>(data), length);
}

void flushNothing(png_structp /*png*/) {}

}  // namespace

std::string pngBytes(const ThumbnailImage& image) {
  const int width = image.width, height = image.height;
  const std::vector<std::uint8_t>& rgba = image.rgba;
  if (width <= 0 || height <= 0 || rgba.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4)
    throw std::invalid_argument("thumbnail: the pixels do not match the picture's size");
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) throw std::runtime_error("thumbnail: libpng cannot start a PNG");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw std::runtime_error("thumbnail: libpng cannot start a PNG");
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y)
    rows[static_cast<std::size_t>(y)] =
        const_cast<png_bytep>(rgba.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width) * 4);
  if (setjmp(png_jmpbuf(png))) {  // libpng reports errors by longjmp
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("thumbnail: libpng failed to write the PNG");
  }
  png_set_write_fn(png, &out, appendToString, flushNothing);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

ThumbnailImage renderSurfaceThumbnail(const io::QuadMesh& surface, const ThumbnailOptions& options) {
  if (options.width < 16 || options.width > 2048 || options.height < 16 || options.height > 2048)
    throw std::invalid_argument("thumbnail: width and height must lie in [16, 2048]");
  if (options.supersampling < 1 || options.supersampling > 4)
    throw std::invalid_argument("thumbnail: supersampling must lie in [1, 4]");
  if (!(options.margin >= 0.0 && options.margin <= 0.4)) throw std::invalid_argument("thumbnail: margin must lie in [0, 0.4]");
  const Eigen::MatrixX3d& V = surface.vertices;
  if (V.rows() == 0 || !V.allFinite()) throw std::invalid_argument("thumbnail: the surface has no finite vertices");
  const Eigen::MatrixX3i T = io::triangulateQuads(surface);
  if (T.rows() == 0) throw std::invalid_argument("thumbnail: the surface has no triangle of positive area");

  // Principal axes, signs fixed by the third moments.
  const Eigen::RowVector3d mean = V.colwise().mean();
  const Eigen::MatrixX3d centred = V.rowwise() - mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(centred.transpose() * centred);
  std::array<Eigen::Vector3d, 3> axis = {eigen.eigenvectors().col(2), eigen.eigenvectors().col(1),
                                         eigen.eigenvectors().col(0)};  // e1 longest … e3 shortest
  for (Eigen::Vector3d& e : axis)
    if ((centred * e).array().cube().sum() < 0.0) e = -e;
  // The viewer on the side most of the surface faces (its front, as the editor colours it).
  Eigen::Vector3d areaNormal = Eigen::Vector3d::Zero();
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    areaNormal += (Eigen::Vector3d(V.row(T(t, 1)) - V.row(T(t, 0)))).cross(Eigen::Vector3d(V.row(T(t, 2)) - V.row(T(t, 0))));
  if (areaNormal.dot(axis[2]) < 0.0) axis[2] = -axis[2];
  const Eigen::Vector3d view = (axis[2] + 0.55 * axis[1] + 0.35 * axis[0]).normalized();  // towards the viewer
  Eigen::Vector3d right = axis[0] - axis[0].dot(view) * view;
  right = right.norm() > 1e-12 ? right.normalized() : axis[1];
  const Eigen::Vector3d up = view.cross(right);  // right, up, view: right-handed

  // Screen coordinates (pixels of the picture, y down) and depth (towards the viewer).
  Eigen::MatrixX3d screen(V.rows(), 3);
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Eigen::Vector3d p = centred.row(i).transpose();
    screen.row(i) << p.dot(right), p.dot(up), p.dot(view);
  }
  {
    const double w = options.width, h = options.height;
    const Eigen::Vector3d lo = screen.colwise().minCoeff(), hi = screen.colwise().maxCoeff();
    const double margin = options.margin * std::min(w, h);
    const double extent = std::max({(hi.x() - lo.x()) / (w - 2.0 * margin), (hi.y() - lo.y()) / (h - 2.0 * margin), 1e-300});
    const Eigen::Vector2d centre = 0.5 * (lo.head<2>() + hi.head<2>());
    for (Eigen::Index i = 0; i < screen.rows(); ++i) {
      screen(i, 0) = 0.5 * w + (screen(i, 0) - centre.x()) / extent;
      screen(i, 1) = 0.5 * h - (screen(i, 1) - centre.y()) / extent;
    }
  }
  // The work is the triangles' bounding boxes in samples: many large triangles over each other (a
  // hostile scene) draw with fewer samples per pixel, and past a bound not at all.
  double boxPixels = 0.0;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (int c = 0; c < 3; ++c) {
      x0 = std::min(x0, screen(T(t, c), 0));
      x1 = std::max(x1, screen(T(t, c), 0));
      y0 = std::min(y0, screen(T(t, c), 1));
      y1 = std::max(y1, screen(T(t, c), 1));
    }
    boxPixels += std::max(0.0, std::min(x1, double(options.width)) - std::max(x0, 0.0) + 1.0) *
                 std::max(0.0, std::min(y1, double(options.height)) - std::max(y0, 0.0) + 1.0);
  }
  constexpr double kSampleBudget = 6.4e7;
  int ss = options.supersampling;
  while (ss > 1 && boxPixels * ss * ss > kSampleBudget) --ss;
  if (boxPixels > kSampleBudget)
    throw std::invalid_argument("thumbnail: the surface's triangles cover the picture " +
                                std::to_string(static_cast<long long>(boxPixels / (options.width * options.height))) +
                                " times over; too many to draw");
  const int W = options.width * ss, H = options.height * ss;
  screen.leftCols<2>() *= ss;

  // Fill: z-buffer, one colour per triangle.
  std::vector<double> depth(static_cast<std::size_t>(W) * static_cast<std::size_t>(H),
                            -std::numeric_limits<double>::infinity());
  std::vector<std::array<float, 3>> colour(depth.size(), {0.0f, 0.0f, 0.0f});
  const Eigen::Vector3d light = (view + 0.45 * up - 0.35 * right).normalized();
  const Eigen::Vector3d front(0.31, 0.66, 1.0), back(1.0, 0.62, 0.26);  // the app's blue and orange
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const Eigen::Vector3d a3 = V.row(T(t, 0)), b3 = V.row(T(t, 1)), c3 = V.row(T(t, 2));
    const Eigen::Vector3d normal = (b3 - a3).cross(c3 - a3);
    if (!(normal.norm() > 0.0)) continue;
    const Eigen::Vector3d n = normal.normalized();
    const bool facing = n.dot(view) >= 0.0;
    const double lambert = std::abs(n.dot(light));
    const Eigen::Vector3d shade = (facing ? front : back) * (0.28 + 0.72 * lambert);
    const Eigen::Vector3d a = screen.row(T(t, 0)), b = screen.row(T(t, 1)), c = screen.row(T(t, 2));
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (std::abs(area) < 1e-12) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        // Barycentric weights of the pixel centre (inside: all of one sign with the area).
        const double wa = ((b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px)) / area;
        const double wb = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) / area;
        const double wc = 1.0 - wa - wb;
        if (wa < 0.0 || wb < 0.0 || wc < 0.0) continue;
        const double z = wa * a.z() + wb * b.z() + wc * c.z();
        const std::size_t k = static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x);
        if (z <= depth[k]) continue;
        depth[k] = z;
        colour[k] = {static_cast<float>(shade.x()), static_cast<float>(shade.y()), static_cast<float>(shade.z())};
      }
  }

  // Box filter down to the picture: colour averaged over the covered samples, alpha = coverage.
  ThumbnailImage image;
  image.width = options.width;
  image.height = options.height;
  std::vector<std::uint8_t>& rgba = image.rgba;
  rgba.assign(static_cast<std::size_t>(options.width) * static_cast<std::size_t>(options.height) * 4, 0);
  for (int y = 0; y < options.height; ++y)
    for (int x = 0; x < options.width; ++x) {
      double r = 0.0, g = 0.0, bl = 0.0;
      int covered = 0;
      for (int sy = 0; sy < ss; ++sy)
        for (int sx = 0; sx < ss; ++sx) {
          const std::size_t k = static_cast<std::size_t>(y * ss + sy) * static_cast<std::size_t>(W) +
                                static_cast<std::size_t>(x * ss + sx);
          if (!std::isfinite(depth[k])) continue;
          r += colour[k][0];
          g += colour[k][1];
          bl += colour[k][2];
          ++covered;
        }
      if (covered == 0) continue;
      const std::size_t o = (static_cast<std::size_t>(y) * static_cast<std::size_t>(options.width) + static_cast<std::size_t>(x)) * 4;
      auto byte = [](double v) { return static_cast<std::uint8_t>(std::clamp(std::lround(255.0 * v), 0L, 255L)); };
      rgba[o] = byte(r / covered);
      rgba[o + 1] = byte(g / covered);
      rgba[o + 2] = byte(bl / covered);
      rgba[o + 3] = byte(static_cast<double>(covered) / (ss * ss));
    }
  return image;
}

std::string surfaceThumbnailPng(const io::QuadMesh& surface, const ThumbnailOptions& options) {
  return pngBytes(renderSurfaceThumbnail(surface, options));
}

}  // namespace devsurf::server
