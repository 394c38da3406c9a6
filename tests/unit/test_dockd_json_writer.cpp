// dockd's JSON writer: every kind of field, escaping, and an object that does not fit never leaving cut off.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "dockcore/drivers/flat_json.hpp"
#include "json_writer.hpp"

#include "CppUTest/TestHarness.h"

TEST_GROUP(JsonWriter){};

TEST(JsonWriter, WritesEveryKindOfFieldAndEscapes) {
  char buf[256];
  dockd::JsonWriter w(buf, sizeof buf);
  const double r[3] = {1.25, -0.5, 1.0 / 0.0};
  const std::uint32_t u[2] = {7, 4000000000u};
  w.str("s", "a\"b\\c\n\x01").boolean("t", true).boolean("f", false).uint("u", 18446744073709551615ull);
  w.sint("i", -42).real("x", 3.14159, 2).real("nan", std::nan(""), 3).reals("r", r, 3, 1).uints("n", u, 2);
  w.str("null", nullptr).str_cut("cut", "abcdef", 3).str_cut("whole", "abc", 3);
  const std::size_t n = w.finish();
  STRCMP_EQUAL(
      "{\"s\":\"a\\\"b\\\\c\\u000a\\u0001\",\"t\":true,\"f\":false,\"u\":18446744073709551615,\"i\":-42,"
      "\"x\":3.14,\"nan\":null,\"r\":[1.2,-0.5,null],\"n\":[7,4000000000],\"null\":\"\",\"cut\":\"abc...\","
      "\"whole\":\"abc\"}",
      buf);
  CHECK_EQUAL(std::strlen(buf), n);
  // What it writes is JSON: the host protocol's own parser reads the flat part back.
  char flat[64];
  dockd::JsonWriter f(flat, sizeof flat);
  f.str("cmd", "dock").uint("seq", 5).boolean("ok", true);
  const std::size_t fn = f.finish();
  dockcore::drivers::FlatJson p;
  CHECK_EQUAL(static_cast<int>(dockcore::drivers::FlatJsonError::kOk), static_cast<int>(p.parse(flat, fn)));
}

TEST(JsonWriter, AnOptionalGroupIsKeptWholeOrDroppedWhole) {
  char buf[40];
  dockd::JsonWriter w(buf, sizeof buf);
  w.uint("a", 1);
  w.optional_group([&] { w.uint("g1", 2).uint("g2", 3); });  // fits: kept
  // The second field of this group does not fit: the first goes with it, and the writer takes fields again.
  w.optional_group([&] { w.uint("h1", 4).str("h2", "0123456789012345678901234567890"); });
  CHECK_TRUE(w.ok());
  w.uint("z", 5);
  CHECK_TRUE(w.finish() > 0);
  STRCMP_EQUAL("{\"a\":1,\"g1\":2,\"g2\":3,\"z\":5}", buf);
}

TEST(JsonWriter, NeverLeavesACutObjectAndRollsBackOptionalGroups) {
  char buf[32];
  dockd::JsonWriter w(buf, sizeof buf);
  w.uint("a", 1);
  const std::size_t m = w.mark();
  w.str("long", "0123456789012345678901234567890");  // does not fit
  CHECK_FALSE(w.ok());
  w.uint("b", 2);  // nothing after an overflow
  CHECK_FALSE(w.ok());
  w.rollback(m);
  CHECK_TRUE(w.ok());
  w.uint("c", 3);
  const std::size_t n = w.finish(true);
  CHECK_EQUAL(14u, n);
  STRCMP_EQUAL("{\"a\":1,\"c\":3}\n", buf);
  // A group marked after an overflow cannot clear it: the object cut before the group stays refused.
  char cut[24];
  dockd::JsonWriter g(cut, sizeof cut);
  g.str("long", "0123456789012345678901234567890");
  const std::size_t gm = g.mark();
  g.uint("opt", 1);
  g.rollback(gm);
  CHECK_FALSE(g.ok());
  CHECK_EQUAL(0u, g.finish());
  // Without a rollback the object is refused whole.
  char small[16];
  dockd::JsonWriter s(small, sizeof small);
  s.str("k", "far too long for sixteen bytes");
  const std::size_t sn = s.finish();
  CHECK_EQUAL(0u, sn);
  // Up to the last byte: the closing brace, a newline and the terminator always have room once a field fits.
  char exact[12];
  dockd::JsonWriter e(exact, sizeof exact);
  e.uint("abcd", 12);  // {"abcd":12 = 10 bytes, + }\n\0 would be 13: refused
  CHECK_FALSE(e.ok());
  char exact2[13];
  dockd::JsonWriter e2(exact2, sizeof exact2);
  e2.uint("abcd", 12);
  CHECK_TRUE(e2.ok());
  const std::size_t n2 = e2.finish(true);
  CHECK_EQUAL(12u, n2);
  STRCMP_EQUAL("{\"abcd\":12}\n", exact2);
  // Fields another writer made, with the separator where one is needed.
  char inner[32];
  dockd::JsonWriter in(inner, sizeof inner);
  in.uint("x", 1).uint("y", 2);
  char outer[48];
  dockd::JsonWriter out(outer, sizeof outer);
  out.fields(in.body(), in.body_len()).uint("z", 3);
  out.finish();
  STRCMP_EQUAL("{\"x\":1,\"y\":2,\"z\":3}", outer);
}
