#pragma once
// A small RAII layer over libharu for the reports: pages, UTF-8 text in an
// embedded TrueType font, vector paths and RGB pictures. Coordinates are
// points (1/72 in) measured from the page's top-left corner, y downwards.
// hpdf.h stays in pdf_document.cpp; every libharu error becomes a PdfError.
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "reports/render_views.hpp"

namespace sailshape {

struct PdfError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class Align { Left, Centre, Right };

struct PdfFonts {
  std::string regular = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  std::string bold = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";
};

class PdfDocument {
 public:
  // Loads and embeds both fonts. Throws PdfError when a font cannot be read.
  explicit PdfDocument(const PdfFonts& fonts = {});
  ~PdfDocument();
  PdfDocument(const PdfDocument&) = delete;
  PdfDocument& operator=(const PdfDocument&) = delete;

  void setInfo(const std::string& title, const std::string& author, const std::string& subject);
  // A4, portrait or landscape; later drawing goes to this page.
  void addPage(bool landscape = false);
  int pageCount() const { return pages_; }
  float pageWidth() const;
  float pageHeight() const;

  // `y` is the text's baseline.
  void text(float x, float y, const std::string& utf8, float size, bool bold = false, const Rgb& colour = {0, 0, 0},
            Align align = Align::Left);
  float textWidth(const std::string& utf8, float size, bool bold = false) const;
  // Words wrapped to `width`; returns the y below the last line.
  float paragraph(float x, float y, float width, const std::string& utf8, float size, bool bold = false,
                  const Rgb& colour = {0, 0, 0}, float leading = 1.35f);

  void line(float x0, float y0, float x1, float y1, float width, const Rgb& colour, bool dashed = false);
  void polyline(const std::vector<std::pair<float, float>>& points, float width, const Rgb& colour,
                bool dashed = false);
  void rect(float x, float y, float w, float h, const Rgb& fill);
  void frame(float x, float y, float w, float h, float width, const Rgb& colour);
  void disc(float x, float y, float radius, const Rgb& fill);
  void image(const RgbImage& picture, float x, float y, float w, float h);

  // Writes to `path` (through a temporary file renamed into place, so a failed
  // save leaves an existing file as it was). Throws PdfError naming the path.
  void save(const std::string& path);

 struct State;  // libharu's handles; public for the C error callback

 private:
  std::unique_ptr<State> s_;
  int pages_ = 0;
};

}  // namespace sailshape
