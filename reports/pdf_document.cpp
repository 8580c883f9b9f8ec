#include "reports/pdf_document.hpp"

#include <hpdf.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <algorithm>
#include <filesystem>
#include <sstream>

namespace sailshape {

struct PdfDocument::State {
  HPDF_Doc doc = nullptr;
  HPDF_Page page = nullptr;
  HPDF_Font regular = nullptr, bold = nullptr;
  HPDF_STATUS error = HPDF_OK, detail = 0;
};

namespace {

// libharu calls this on every error; the status is turned into an exception
// by check() once control is back in C++ (throwing through C is undefined).
void onError(HPDF_STATUS error, HPDF_STATUS detail, void* user) {
  auto* state = static_cast<PdfDocument::State*>(user);
  if (state->error == HPDF_OK) {
    state->error = error;
    state->detail = detail;
  }
}

// The ToUnicode CMap of a font in libharu's UTF-8 encoding. Its text codes are
// the characters' UTF-16 code units (CID = code, Identity-H), so each code maps to
// itself. libharu 2.3 attaches its encoding CMap instead, which maps codes to CIDs
// (begincidrange), a form a ToUnicode CMap may not use: poppler warns "Invalid
// 'begincidrange' operator in ToUnicode CMap" for every font on every page. The
// ranges stay within one high byte, as bfrange requires.
std::string identityToUnicodeCMap() {
  std::string cmap =
      "/CIDInit /ProcSet findresource begin\n12 dict begin\nbegincmap\n"
      "/CIDSystemInfo << /Registry (Adobe) /Ordering (UCS) /Supplement 0 >> def\n"
      "/CMapName /Adobe-Identity-UCS def\n/CMapType 2 def\n"
      "1 begincodespacerange\n<0000> <FFFF>\nendcodespacerange\n";
  char buf[48];
  for (int block = 0; block < 256; block += 100) {  // at most 100 entries per bfrange block
    const int n = std::min(100, 256 - block);
    cmap += std::to_string(n) + " beginbfrange\n";
    for (int hi = block; hi < block + n; ++hi) {
      std::snprintf(buf, sizeof(buf), "<%02X00> <%02XFF> <%02X00>\n", hi, hi, hi);
      cmap += buf;
    }
    cmap += "endbfrange\n";
  }
  return cmap + "endcmap\nCMapName currentdict /CMap defineresource pop\nend\nend\n";
}

std::string hex(unsigned long v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "0x%04lX", v);
  return buf;
}

}  // namespace

#define PDF_CHECK(state, what)                                                                               \
  do {                                                                                                       \
    if ((state)->error != HPDF_OK) {                                                                         \
      const auto e = (state)->error, d = (state)->detail;                                                    \
      (state)->error = HPDF_OK;                                                                              \
      throw PdfError(std::string("[PdfDocument] ") + (what) + ": libharu error " + hex(e) + " (detail " +   \
                     std::to_string(d) + ")");                                                               \
    }                                                                                                        \
  } while (0)

PdfDocument::PdfDocument(const PdfFonts& fonts) : s_(std::make_unique<State>()) {
  s_->doc = HPDF_New(onError, s_.get());
  if (!s_->doc) throw PdfError("[PdfDocument] libharu could not create a document (out of memory)");
  HPDF_SetCompressionMode(s_->doc, HPDF_COMP_ALL);
  HPDF_UseUTFEncodings(s_->doc);
  HPDF_SetCurrentEncoder(s_->doc, "UTF-8");
  PDF_CHECK(s_, "UTF-8 encoding");
  auto load = [&](const std::string& path) {
    if (!std::filesystem::is_regular_file(path))
      throw PdfError("[PdfDocument] font " + path + " not found (Debian: fonts-dejavu-core)");
    const char* name = HPDF_LoadTTFontFromFile(s_->doc, path.c_str(), HPDF_TRUE);  // embedded
    PDF_CHECK(s_, "loading font " + path);
    HPDF_Font font = HPDF_GetFont(s_->doc, name, "UTF-8");
    PDF_CHECK(s_, "font " + path + " in UTF-8");
    auto* to_unicode = static_cast<HPDF_Dict>(HPDF_Dict_GetItem(font, "ToUnicode", HPDF_OCLASS_DICT));
    if (to_unicode && to_unicode->stream) {
      HPDF_MemStream_FreeData(to_unicode->stream);
      HPDF_Stream_WriteStr(to_unicode->stream, identityToUnicodeCMap().c_str());
      PDF_CHECK(s_, "ToUnicode map of " + path);
    }
    return font;
  };
  try {
    s_->regular = load(fonts.regular);
    s_->bold = load(fonts.bold);
  } catch (...) {
    HPDF_Free(s_->doc);
    throw;
  }
}

PdfDocument::~PdfDocument() {
  if (s_ && s_->doc) HPDF_Free(s_->doc);
}

void PdfDocument::setInfo(const std::string& title, const std::string& author, const std::string& subject) {
  HPDF_SetInfoAttr(s_->doc, HPDF_INFO_TITLE, title.c_str());
  HPDF_SetInfoAttr(s_->doc, HPDF_INFO_AUTHOR, author.c_str());
  HPDF_SetInfoAttr(s_->doc, HPDF_INFO_SUBJECT, subject.c_str());
  HPDF_SetInfoAttr(s_->doc, HPDF_INFO_CREATOR, "sailshape");
  PDF_CHECK(s_, "document info");
}

void PdfDocument::addPage(bool landscape) {
  s_->page = HPDF_AddPage(s_->doc);
  HPDF_Page_SetSize(s_->page, HPDF_PAGE_SIZE_A4, landscape ? HPDF_PAGE_LANDSCAPE : HPDF_PAGE_PORTRAIT);
  PDF_CHECK(s_, "adding page " + std::to_string(pages_ + 1));
  ++pages_;
}

float PdfDocument::pageWidth() const { return s_->page ? HPDF_Page_GetWidth(s_->page) : 0.f; }
float PdfDocument::pageHeight() const { return s_->page ? HPDF_Page_GetHeight(s_->page) : 0.f; }

float PdfDocument::textWidth(const std::string& utf8, float size, bool bold) const {
  if (!s_->page || utf8.empty()) return 0.f;
  HPDF_Page_SetFontAndSize(s_->page, bold ? s_->bold : s_->regular, size);
  const float w = HPDF_Page_TextWidth(s_->page, utf8.c_str());
  PDF_CHECK(s_, "measuring \"" + utf8 + "\"");
  return w;
}

void PdfDocument::text(float x, float y, const std::string& utf8, float size, bool bold, const Rgb& colour,
                       Align align) {
  if (!s_->page) throw PdfError("[PdfDocument] text before the first page");
  if (utf8.empty()) return;
  if (align != Align::Left) {
    const float w = textWidth(utf8, size, bold);
    x -= align == Align::Centre ? w / 2 : w;
  }
  HPDF_Page_BeginText(s_->page);
  HPDF_Page_SetFontAndSize(s_->page, bold ? s_->bold : s_->regular, size);
  HPDF_Page_SetRGBFill(s_->page, colour[0], colour[1], colour[2]);
  HPDF_Page_TextOut(s_->page, x, pageHeight() - y, utf8.c_str());
  HPDF_Page_EndText(s_->page);
  PDF_CHECK(s_, "writing \"" + utf8 + "\"");
}

float PdfDocument::paragraph(float x, float y, float width, const std::string& utf8, float size, bool bold,
                             const Rgb& colour, float leading) {
  std::istringstream words(utf8);
  std::string word, current;
  auto flush = [&] {
    if (current.empty()) return;
    text(x, y, current, size, bold, colour);
    y += size * leading;
    current.clear();
  };
  while (words >> word) {
    const std::string candidate = current.empty() ? word : current + " " + word;
    if (!current.empty() && textWidth(candidate, size, bold) > width) {
      flush();
      current = word;
    } else {
      current = candidate;
    }
  }
  flush();
  return y;
}

void PdfDocument::line(float x0, float y0, float x1, float y1, float width, const Rgb& colour, bool dashed) {
  polyline({{x0, y0}, {x1, y1}}, width, colour, dashed);
}

void PdfDocument::polyline(const std::vector<std::pair<float, float>>& points, float width, const Rgb& colour,
                           bool dashed) {
  if (!s_->page) throw PdfError("[PdfDocument] drawing before the first page");
  if (points.size() < 2) return;
  const float h = pageHeight();
  HPDF_Page_SetLineWidth(s_->page, width);
  HPDF_Page_SetRGBStroke(s_->page, colour[0], colour[1], colour[2]);
  HPDF_Page_SetLineJoin(s_->page, HPDF_ROUND_JOIN);
  HPDF_Page_SetLineCap(s_->page, HPDF_ROUND_END);
  const HPDF_UINT16 dash[] = {4, 3};
  if (dashed) HPDF_Page_SetDash(s_->page, dash, 2, 0);
  HPDF_Page_MoveTo(s_->page, points[0].first, h - points[0].second);
  for (size_t i = 1; i < points.size(); ++i) HPDF_Page_LineTo(s_->page, points[i].first, h - points[i].second);
  HPDF_Page_Stroke(s_->page);
  if (dashed) HPDF_Page_SetDash(s_->page, nullptr, 0, 0);
  PDF_CHECK(s_, "drawing a path");
}

void PdfDocument::rect(float x, float y, float w, float hgt, const Rgb& fill) {
  if (!s_->page) throw PdfError("[PdfDocument] drawing before the first page");
  HPDF_Page_SetRGBFill(s_->page, fill[0], fill[1], fill[2]);
  HPDF_Page_Rectangle(s_->page, x, pageHeight() - y - hgt, w, hgt);
  HPDF_Page_Fill(s_->page);
  PDF_CHECK(s_, "filling a rectangle");
}

void PdfDocument::frame(float x, float y, float w, float hgt, float width, const Rgb& colour) {
  if (!s_->page) throw PdfError("[PdfDocument] drawing before the first page");
  HPDF_Page_SetLineWidth(s_->page, width);
  HPDF_Page_SetRGBStroke(s_->page, colour[0], colour[1], colour[2]);
  HPDF_Page_Rectangle(s_->page, x, pageHeight() - y - hgt, w, hgt);
  HPDF_Page_Stroke(s_->page);
  PDF_CHECK(s_, "framing a rectangle");
}

void PdfDocument::disc(float x, float y, float radius, const Rgb& fill) {
  if (!s_->page) throw PdfError("[PdfDocument] drawing before the first page");
  HPDF_Page_SetRGBFill(s_->page, fill[0], fill[1], fill[2]);
  HPDF_Page_Circle(s_->page, x, pageHeight() - y, radius);
  HPDF_Page_Fill(s_->page);
  PDF_CHECK(s_, "drawing a disc");
}

void PdfDocument::image(const RgbImage& picture, float x, float y, float w, float hgt) {
  if (!s_->page) throw PdfError("[PdfDocument] drawing before the first page");
  if (picture.width <= 0 || picture.height <= 0 ||
      picture.rgb.size() != size_t(picture.width) * size_t(picture.height) * 3)
    throw PdfError("[PdfDocument] picture of " + std::to_string(picture.width) + "×" + std::to_string(picture.height) +
                   " px holds " + std::to_string(picture.rgb.size()) + " bytes");
  HPDF_Image img = HPDF_LoadRawImageFromMem(s_->doc, picture.rgb.data(), picture.width, picture.height,
                                            HPDF_CS_DEVICE_RGB, 8);
  PDF_CHECK(s_, "adding a picture");
  HPDF_Page_DrawImage(s_->page, img, x, pageHeight() - y - hgt, w, hgt);
  PDF_CHECK(s_, "placing a picture");
}

void PdfDocument::save(const std::string& path) {
  const std::string tmp = path + ".part";
  HPDF_SaveToFile(s_->doc, tmp.c_str());
  if (s_->error != HPDF_OK) {
    s_->error = HPDF_OK;
    std::remove(tmp.c_str());
    throw PdfError("[PdfDocument] cannot write " + path + (errno ? std::string(": ") + std::strerror(errno) : ""));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw PdfError("[PdfDocument] cannot write " + path + ": " + ec.message());
  }
}

}  // namespace sailshape
