// CoLa framing, telegram split, field codec and the stream decoder's documented fault behaviour.
#include "acquisition/cola.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace sailshape {
namespace {

std::string bytes(std::initializer_list<int> list) {
  std::string out;
  for (int b : list) out += static_cast<char>(b);
  return out;
}

std::vector<std::string> drain(ColaStreamDecoder& d) {
  std::vector<std::string> out;
  while (auto p = d.next()) out.push_back(*p);
  return out;
}

TEST(ColaFrame, BinaryFrameMatchesRecordedRequest) {
  // The LMS111 recording's request, byte for byte: length 0x13, XOR checksum 0x24.
  const std::string expected = bytes({2, 2, 2, 2, 0, 0, 0, 0x13}) + "sRN FirmwareVersion" + bytes({0x24});
  EXPECT_EQ(frameCola(ColaDialect::kBinary, "sRN FirmwareVersion"), expected);
  // Login with level 3 and the "authorised client" password hash, checksum 0xB3 as recorded.
  const std::string login = "sMN SetAccessMode " + bytes({0x03, 0xf4, 0x72, 0x47, 0x44});
  const std::string framed = frameCola(ColaDialect::kBinary, login);
  EXPECT_EQ(static_cast<unsigned char>(framed.back()), 0xb3);
  EXPECT_EQ(framed.size(), login.size() + 9);
}

TEST(ColaFrame, AsciiFrameIsStxPayloadEtx) {
  EXPECT_EQ(frameCola(ColaDialect::kAscii, "sRN LMPscancfg"), "\x02sRN LMPscancfg\x03");
  EXPECT_THROW(frameCola(ColaDialect::kAscii, std::string("sRN a\x03")), ColaError);
  EXPECT_THROW(frameCola(ColaDialect::kBinary, ""), ColaError);
  EXPECT_THROW(frameCola(ColaDialect::kBinary, std::string(kColaMaxPayloadBytes + 1, 's')), ColaError);
}

TEST(ColaFrame, DialectNames) {
  EXPECT_EQ(parseColaDialect("Binary"), ColaDialect::kBinary);
  EXPECT_EQ(parseColaDialect("cola-a"), ColaDialect::kAscii);
  EXPECT_STREQ(colaDialectName(ColaDialect::kAscii), "ascii");
  EXPECT_THROW(parseColaDialect("hex"), ColaError);
}

TEST(ColaTelegramSplit, TypeNameArgumentsAndTrailingSpace) {
  const ColaTelegram a = splitColaTelegram("sAN SetAccessMode " + bytes({1}));
  EXPECT_EQ(a.type, "sAN");
  EXPECT_EQ(a.name, "SetAccessMode");
  EXPECT_EQ(a.arguments, bytes({1}));

  // The device answers a write with a trailing space and no argument; the split keeps that for re-encoding.
  const ColaTelegram w = splitColaTelegram("sWA EIHstCola ");
  EXPECT_EQ(w.name, "EIHstCola");
  EXPECT_TRUE(w.arguments.empty());
  EXPECT_TRUE(w.space_after_name);
  EXPECT_EQ(joinColaTelegram(w), "sWA EIHstCola ");

  const ColaTelegram r = splitColaTelegram("sRN FirmwareVersion");
  EXPECT_FALSE(r.space_after_name);
  EXPECT_EQ(joinColaTelegram(r), "sRN FirmwareVersion");

  // Binary error reply as the LMS511 sends it for an unknown variable: "sFA" + u16 code 3.
  const ColaTelegram f = splitColaTelegram("sFA" + bytes({0, 3}));
  EXPECT_EQ(f.type, "sFA");
  EXPECT_TRUE(f.name.empty());
  EXPECT_EQ(ColaReader(ColaDialect::kBinary, f.arguments, "sFA").u16("code"), 3);
  EXPECT_EQ(joinColaTelegram(f), "sFA" + bytes({0, 3}));

  EXPECT_THROW(splitColaTelegram("xRN foo"), ColaError);
  EXPECT_THROW(splitColaTelegram("sRNfoo"), ColaError);
  EXPECT_THROW(splitColaTelegram("sRN "), ColaError);
  EXPECT_THROW(splitColaTelegram("sRN"), ColaError);  // found by the fuzz target: it re-joined as "sRN "
  EXPECT_EQ(splitColaTelegram("sFA").type, "sFA");
  EXPECT_EQ(colaPayload("sEN", "LMDscandata", "1"), "sEN LMDscandata 1");
}

TEST(ColaFields, BinaryIsBigEndian) {
  ColaWriter w(ColaDialect::kBinary);
  w.u8(1).u16(0x1388).u32(0x0114097a).i32(-450000).f32(1.0f).fixedString("DIST1").string("SN");
  const std::string expected = bytes({1, 0x13, 0x88, 0x01, 0x14, 0x09, 0x7a, 0xff, 0xf9, 0x22, 0x30,
                                      0x3f, 0x80, 0, 0}) + "DIST1" + bytes({0, 2}) + "SN";
  EXPECT_EQ(w.bytes(), expected);

  ColaReader r(ColaDialect::kBinary, w.bytes(), "test");
  EXPECT_EQ(r.u8("a"), 1);
  EXPECT_EQ(r.u16("b"), 5000);
  EXPECT_EQ(r.u32("c"), 18090362u);
  EXPECT_EQ(r.i32("d"), -450000);
  EXPECT_EQ(r.f32("e"), 1.0f);
  EXPECT_EQ(r.fixedString(5, "f"), "DIST1");
  EXPECT_EQ(r.string("g"), "SN");
  EXPECT_TRUE(r.atEnd());
  EXPECT_NO_THROW(r.expectEnd());
  EXPECT_THROW(r.u8("past the end"), ColaError);
}

TEST(ColaFields, AsciiIsHexTokens) {
  ColaWriter w(ColaDialect::kAscii);
  w.u8(0).u16(0x1388).u32(0x0114097a).i32(-450000).f32(1.0f).f32(0.0f).fixedString("DIST1").string("not defined");
  EXPECT_EQ(w.bytes(), "0 1388 114097A FFF92230 3F800000 00000000 DIST1 B not defined");

  ColaReader r(ColaDialect::kAscii, w.bytes(), "test");
  EXPECT_EQ(r.u8("a"), 0);
  EXPECT_EQ(r.u16("b"), 5000);
  EXPECT_EQ(r.u32("c"), 18090362u);
  EXPECT_EQ(r.i32("d"), -450000);
  EXPECT_EQ(r.f32("e"), 1.0f);
  EXPECT_EQ(r.f32("f"), 0.0f);
  EXPECT_EQ(r.fixedString(5, "g"), "DIST1");
  EXPECT_EQ(r.string("h"), "not defined");  // the length, not the space, ends the text
  EXPECT_TRUE(r.atEnd());
}

TEST(ColaFields, AsciiDecimalWithSign) {
  // mLMPsetscancfg in CoLa A is written with signed decimals: +2500 +1 +1667 -50000 +1850000.
  ColaReader r(ColaDialect::kAscii, "+2500 +1 +1667 -50000 +1850000", "mLMPsetscancfg");
  EXPECT_EQ(r.u32("frequency"), 2500u);
  EXPECT_EQ(r.i16("sectors"), 1);
  EXPECT_EQ(r.u32("resolution"), 1667u);
  EXPECT_EQ(r.i32("start"), -50000);
  EXPECT_EQ(r.i32("stop"), 1850000);
  ColaWriter w(ColaDialect::kAscii);
  w.token("+2500").u8(1);
  EXPECT_EQ(w.bytes(), "+2500 1");
  ColaWriter b(ColaDialect::kBinary);
  EXPECT_THROW(b.token("+1"), ColaError);
}

TEST(ColaFields, MalformedFieldsNameTheField) {
  try {
    ColaReader(ColaDialect::kBinary, bytes({1}), "LMDscandata").u16("version");
    FAIL() << "no exception";
  } catch (const ColaError& e) {
    EXPECT_NE(std::string(e.what()).find("[LMDscandata] version"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "G1", "t").u16("x"), ColaError);       // not hex
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "1FF", "t").u8("x"), ColaError);       // too many digits
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "+", "t").u8("x"), ColaError);         // sign only
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "-40000", "t").i16("x"), ColaError);  // below -32768
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "+4x", "t").u8("x"), ColaError);       // not decimal
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "+300", "t").u8("x"), ColaError);      // out of range
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "", "t").u8("x"), ColaError);          // missing
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "DIST", "t").fixedString(5, "x"), ColaError);
  EXPECT_THROW(ColaReader(ColaDialect::kBinary, "DIS", "t").fixedString(5, "x"), ColaError);
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "5 abc", "t").string("x"), ColaError);  // text too short
  EXPECT_THROW(ColaReader(ColaDialect::kAscii, "3abc", "t").string("x"), ColaError);   // not hex length
  EXPECT_THROW(ColaReader(ColaDialect::kBinary, bytes({0, 9}) + "abc", "t").string("x"), ColaError);
  ColaReader extra(ColaDialect::kBinary, bytes({1, 2}), "t");
  extra.u8("x");
  EXPECT_THROW(extra.expectEnd(), ColaError);
  ColaWriter w(ColaDialect::kAscii);
  EXPECT_THROW(w.fixedString("A B"), ColaError);
  EXPECT_THROW(w.string(std::string(70000, 'a')), ColaError);
}

TEST(ColaStream, FramesSplitAtEveryByteComeOutOnce) {
  const std::string a = frameCola(ColaDialect::kBinary, "sRN FirmwareVersion");
  const std::string b = frameCola(ColaDialect::kBinary, "sAN SetAccessMode " + bytes({1}));
  const std::string wire = a + b;
  ColaStreamDecoder d;
  std::vector<std::string> got;
  for (char c : wire) {
    d.feed(std::string(1, c));
    for (auto& p : drain(d)) got.push_back(p);
  }
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], "sRN FirmwareVersion");
  EXPECT_EQ(got[1], "sAN SetAccessMode " + bytes({1}));
  EXPECT_EQ(d.stats().frames, 2u);
  EXPECT_EQ(d.stats().garbage_bytes, 0u);
  EXPECT_EQ(d.bufferedBytes(), 0u);
}

TEST(ColaStream, FrameSplitMidwayWaitsForTheRest) {
  const std::string f = frameCola(ColaDialect::kBinary, "sEA LMDscandata " + bytes({1}));
  ColaStreamDecoder d;
  d.feed(f.substr(0, f.size() / 2));
  EXPECT_FALSE(d.next().has_value());
  EXPECT_EQ(d.bufferedBytes(), f.size() / 2);
  d.feed(f.substr(f.size() / 2));
  auto p = d.next();
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(*p, "sEA LMDscandata " + bytes({1}));
  EXPECT_EQ(d.stats().garbage_bytes, 0u);
}

TEST(ColaStream, GarbageBetweenFramesIsSkippedAndCounted) {
  const std::string a = frameCola(ColaDialect::kBinary, "sMN Run");
  const std::string b = frameCola(ColaDialect::kBinary, "sAN Run " + bytes({1}));
  const std::string garbage = "noise" + bytes({2, 2, 0x41, 2});  // even partial start markers
  ColaStreamDecoder d;
  d.feed(garbage + a + garbage + b + "xx");
  const auto got = drain(d);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], "sMN Run");
  EXPECT_EQ(got[1], "sAN Run " + bytes({1}));
  EXPECT_EQ(d.stats().garbage_bytes, 2 * garbage.size() + 2);
  EXPECT_EQ(d.stats().bad_checksum, 0u);
}

TEST(ColaStream, BadChecksumFrameIsDroppedAndCounted) {
  std::string bad = frameCola(ColaDialect::kBinary, "sSN LMDscandata " + bytes({0, 1, 2}));
  bad.back() = static_cast<char>(bad.back() ^ 0x5a);
  const std::string good = frameCola(ColaDialect::kBinary, "sMN Run");
  ColaStreamDecoder d;
  d.feed(bad + good);
  const auto got = drain(d);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], "sMN Run");
  EXPECT_EQ(d.stats().bad_checksum, 1u);
  EXPECT_EQ(d.stats().frames, 1u);
}

TEST(ColaStream, BogusLengthInGarbageDoesNotSwallowTheNextFrame) {
  // Garbage with a start marker and a plausible length: the frame it announces covers a real frame.
  const std::string good = frameCola(ColaDialect::kBinary, "sMN LMCstartmeas");
  const std::string garbage = bytes({2, 2, 2, 2, 0, 0, 0, 0x10, 'z'});
  ColaStreamDecoder d;
  d.feed(garbage + good + std::string(16, 'q'));
  const auto got = drain(d);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], "sMN LMCstartmeas");
  EXPECT_EQ(d.stats().bad_checksum, 1u);
}

TEST(ColaStream, LengthOverTheLimitIsSkipped) {
  ColaStreamDecoder d({ColaDialect::kBinary, 100});
  const std::string good = frameCola(ColaDialect::kBinary, "sMN Run");
  d.feed(bytes({2, 2, 2, 2, 0, 0, 1, 0}) + bytes({2, 2, 2, 2, 0, 0, 0, 0}) + good);
  const auto got = drain(d);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(d.stats().bad_length, 2u);
  EXPECT_THROW(ColaStreamDecoder({ColaDialect::kBinary, 0}), ColaError);
}

// A damaged length field that announces more than its frame holds (still under the limit) is not waited
// for once a complete good frame has come after it: the frames after it come out at once, whether the
// bytes arrive together (a capture replayed) or one by one (a live stream).
TEST(ColaStream, LengthRunningPastTheNextFrameIsSkippedToThatFrame) {
  std::string damaged = frameCola(ColaDialect::kBinary, "sSN LMDscandata " + bytes({0, 1, 2, 3}));
  damaged[6] = 0x7f;  // announces 0x7f00 + 21 bytes
  const std::string b = frameCola(ColaDialect::kBinary, "sMN Run");
  const std::string c = frameCola(ColaDialect::kBinary, "sAN Run " + bytes({1}));
  ColaStreamDecoder whole;
  whole.feed(damaged + b + c);
  EXPECT_EQ(drain(whole), (std::vector<std::string>{"sMN Run", "sAN Run " + bytes({1})}));
  EXPECT_EQ(whole.stats().bad_length, 1u);
  EXPECT_EQ(whole.stats().bad_checksum, 0u);
  EXPECT_EQ(whole.stats().garbage_bytes, damaged.size());
  EXPECT_EQ(whole.bufferedBytes(), 0u);

  ColaStreamDecoder trickle;
  std::vector<std::string> got;
  size_t fed = 0, first_at = 0;
  for (char ch : damaged + b + c) {
    trickle.feed(std::string(1, ch));
    ++fed;
    for (auto& p : drain(trickle)) {
      if (got.empty()) first_at = fed;
      got.push_back(p);
    }
  }
  EXPECT_EQ(got, (std::vector<std::string>{"sMN Run", "sAN Run " + bytes({1})}));
  EXPECT_EQ(first_at, damaged.size() + b.size());  // as soon as the good frame is complete
  // A frame still arriving, with no good frame after its start, is waited for.
  ColaStreamDecoder waiting;
  waiting.feed(b.substr(0, b.size() - 1));
  EXPECT_FALSE(waiting.next().has_value());
  EXPECT_EQ(waiting.stats().bad_length, 0u);
}

TEST(ColaStream, PayloadHoldingStartMarkerBytesIsNotCut) {
  // The LMS111 answers LIDinputstate with 02 02 02 02 inside the payload.
  const std::string payload = "sRA LIDinputstate " + bytes({0, 1, 0, 0, 0, 0, 2, 2, 2, 2, 0, 0});
  const std::string f = frameCola(ColaDialect::kBinary, payload);
  EXPECT_EQ(static_cast<unsigned char>(f.back()), 0x21);  // '!' as recorded
  ColaStreamDecoder d;
  d.feed(f + f);
  const auto got = drain(d);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[1], payload);
}

TEST(ColaStream, AsciiResynchronisesOnANewStart) {
  ColaStreamDecoder d({ColaDialect::kAscii});
  d.feed("junk\x02sRA LMDscan");  // cut off by a new frame: dropped
  EXPECT_FALSE(d.next().has_value());
  d.feed("\x02sAN Run 1\x03  \x02\x03\x02sEA LMDscandata 1");
  auto first = d.next();
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(*first, "sAN Run 1");
  EXPECT_FALSE(d.next().has_value());  // second frame not finished yet
  d.feed("\x03");
  auto second = d.next();
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(*second, "sEA LMDscandata 1");
  EXPECT_EQ(d.stats().unterminated, 2u);  // the cut frame and the empty one
  EXPECT_EQ(d.stats().frames, 2u);
}

}  // namespace
}  // namespace sailshape
