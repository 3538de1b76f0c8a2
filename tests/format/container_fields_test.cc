// The fields visitor (container_fields.h): floats, nested records, counted and Length arrays,
// through the sizer, writer, reader and printer. Expected bytes are written out by hand from the
// encoding rules, never produced by the code under test.
#include "calf/format/container_fields.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace calf::container {
namespace {

using Bytes = std::vector<uint8_t>;

struct Point {
  float x = 0;
  double y = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.x, "x", FloatRule::kFinite);
    v(s.y, "y");  // any value, NaN included
  }
};

struct Shape {
  uint16_t id = 0;
  Point centre;
  std::vector<uint32_t> keys;
  std::vector<Point> points;
  float weights[2] = {0, 0};
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.id, "id", Range{1, 100});
    v(s.centre, "centre");
    v(s.keys, "keys", Range{0, 3});
    v(s.points, "points", Length{s.id});
    v(s.weights, "weights", FloatRule::kFinite);
  }
};

struct Many {
  std::vector<double> values;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.values, "values");
  }
};

Shape example() {
  Shape s;
  s.id = 1;
  s.centre.x = 1.0f;
  s.centre.y = -2.0;
  s.keys = {7, 0x01020304};
  s.points = {Point{0.5f, 0.25}};
  s.weights[0] = -0.0f;
  s.weights[1] = 3.0f;
  return s;
}

// Little-endian IEEE 754: 1.0f = 3F800000, -2.0 = C000000000000000, 0.5f = 3F000000,
// 0.25 = 3FD0000000000000, -0.0f = 80000000, 3.0f = 40400000.
const Bytes kExampleBytes = {
    0x01, 0x00,                                      // id
    0x00, 0x00, 0x80, 0x3F,                          // centre.x
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0,  // centre.y
    0x02, 0x00, 0x00, 0x00,                          // keys.count
    0x07, 0x00, 0x00, 0x00, 0x04, 0x03, 0x02, 0x01,  // keys
    0x00, 0x00, 0x00, 0x3F,                          // points[0].x
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xD0, 0x3F,  // points[0].y
    0x00, 0x00, 0x00, 0x80,                          // weights[0]
    0x00, 0x00, 0x40, 0x40,                          // weights[1]
};

FieldReader reader(const Bytes& b) {
  return FieldReader(b, ErrorId::kContainerTruncated, ErrorId::kContainerDirectoryFormat, "test");
}

TEST(ContainerFields, WritesTheDeclaredBytes) {
  Bytes out;
  ASSERT_TRUE(write_fields(example(), out).ok());
  EXPECT_EQ(out, kExampleBytes);
  FieldSizer sizer;
  const Shape shape = example();
  Shape::fields(shape, sizer);
  EXPECT_EQ(sizer.size(), kExampleBytes.size());
  static_assert(fixed_size<Point>() == 12);
  EXPECT_EQ(min_size<Shape>(), 2u + 12 + 4 + 8);  // no keys, no points
}

TEST(ContainerFields, ReadsBackEveryValueExactly) {
  FieldReader r = reader(kExampleBytes);
  Shape s;
  ASSERT_TRUE(read_fields(s, r).ok()) << r.status().to_string();
  EXPECT_EQ(r.remaining(), 0u);
  EXPECT_EQ(s.id, 1);
  EXPECT_EQ(s.centre.x, 1.0f);
  EXPECT_EQ(s.centre.y, -2.0);
  EXPECT_EQ(s.keys, (std::vector<uint32_t>{7, 0x01020304}));
  ASSERT_EQ(s.points.size(), 1u);
  EXPECT_EQ(s.points[0].x, 0.5f);
  EXPECT_EQ(s.points[0].y, 0.25);
  EXPECT_TRUE(std::signbit(s.weights[0]));
  EXPECT_EQ(s.weights[1], 3.0f);
}

TEST(ContainerFields, FloatBitsSurviveARoundTrip) {
  // A NaN with a payload, subnormals and the extremes keep their exact bits where allowed.
  Point p;
  p.x = std::numeric_limits<float>::denorm_min();
  p.y = std::bit_cast<double>(uint64_t{0x7FF800000000ABCDull});
  Bytes out;
  ASSERT_TRUE(write_fields(p, out).ok());
  ASSERT_EQ(out.size(), 12u);
  EXPECT_EQ(out[0], 0x01);
  EXPECT_EQ(out[11], 0x7F);
  FieldReader r = reader(out);
  Point q;
  ASSERT_TRUE(read_fields(q, r).ok());
  EXPECT_EQ(std::bit_cast<uint32_t>(q.x), 1u);
  EXPECT_EQ(std::bit_cast<uint64_t>(q.y), 0x7FF800000000ABCDull);
}

TEST(ContainerFields, ReadingAForbiddenFloatNamesTheField) {
  Bytes b = kExampleBytes;
  b[26] = 0x00, b[27] = 0x00, b[28] = 0x80, b[29] = 0x7F;  // points[0].x = +inf
  FieldReader r = reader(b);
  Shape s;
  const Status st = read_fields(s, r);
  EXPECT_EQ(st.id(), ErrorId::kContainerDirectoryFormat);  // the reader's invalid id
  EXPECT_NE(st.message().find("points[0].x inf is not finite"), std::string::npos) << st.message();

  b = kExampleBytes;
  b[44] = 0xC0, b[45] = 0x7F;  // weights[1] = NaN
  FieldReader r2 = reader(b);
  const Status st2 = read_fields(s, r2);
  EXPECT_EQ(st2.id(), ErrorId::kContainerDirectoryFormat);
  EXPECT_NE(st2.message().find("weights[1] nan"), std::string::npos) << st2.message();
}

TEST(ContainerFields, WritingAForbiddenFloatIsMisuse) {
  Shape s = example();
  s.centre.x = std::nanf("");
  Bytes out;
  Status st = write_fields(s, out, "shape");
  EXPECT_EQ(st.id(), ErrorId::kContainerWriterMisuse);
  EXPECT_NE(st.message().find("shape: centre.x nan is not finite"), std::string::npos)
      << st.message();
  s = example();
  s.weights[0] = -std::numeric_limits<float>::infinity();
  out.clear();
  EXPECT_EQ(write_fields(s, out).id(), ErrorId::kContainerWriterMisuse);
  // An unconstrained float may be anything.
  s = example();
  s.centre.y = std::numeric_limits<double>::infinity();
  out.clear();
  EXPECT_TRUE(write_fields(s, out).ok());
}

TEST(ContainerFields, ACountIsCheckedAgainstItsRangeAndTheBytesLeft) {
  // keys.count 4 exceeds the Range max 3: the limit id.
  Bytes b = kExampleBytes;
  b[14] = 4;
  FieldReader r = reader(b);
  Shape s;
  EXPECT_EQ(read_fields(s, r).id(), ErrorId::kContainerLimit);

  // A huge count with few bytes left fails before any allocation (and quickly).
  const Bytes huge = {0xFF, 0xFF, 0xFF, 0xFF, 1, 2, 3, 4, 5, 6, 7, 8};
  FieldReader r2 = reader(huge);
  Many m;
  const Status st = read_fields(m, r2);
  EXPECT_EQ(st.id(), ErrorId::kContainerTruncated);
  EXPECT_NE(st.message().find("values needs 34359738360 bytes"), std::string::npos) << st.message();
  EXPECT_TRUE(m.values.empty());

  // A Length array longer than the bytes left: the short id, nothing allocated.
  b = kExampleBytes;
  b[0] = 100;  // id = 100 points, 40 bytes left
  FieldReader r3 = reader(b);
  EXPECT_EQ(read_fields(s, r3).id(), ErrorId::kContainerTruncated);
  EXPECT_TRUE(s.points.empty());
}

TEST(ContainerFields, ALengthArrayOfAnotherLengthIsMisuse) {
  Shape s = example();
  s.points.push_back(Point{});
  Bytes out;
  const Status st = write_fields(s, out);
  EXPECT_EQ(st.id(), ErrorId::kContainerWriterMisuse);
  EXPECT_NE(st.message().find("points holds 2 elements, not 1"), std::string::npos) << st.message();
  s = example();
  s.keys = {1, 2, 3, 4};
  out.clear();
  EXPECT_EQ(write_fields(s, out).id(), ErrorId::kContainerWriterMisuse);
}

TEST(ContainerFields, TruncationAnywhereIsTheShortId) {
  for (size_t n = 0; n < kExampleBytes.size(); ++n) {
    const Bytes b(kExampleBytes.begin(), kExampleBytes.begin() + static_cast<std::ptrdiff_t>(n));
    FieldReader r = reader(b);
    Shape s;
    EXPECT_EQ(read_fields(s, r).id(), ErrorId::kContainerTruncated) << n << " bytes";
  }
}

TEST(ContainerFields, PrintsPathsAndExactFloats) {
  Shape s = example();
  s.centre.y = 0.1;
  s.points[0].y = std::numeric_limits<double>::quiet_NaN();
  const auto e = print_fields(s);
  std::vector<std::string> names, values;
  for (const auto& x : e) names.push_back(x.name), values.push_back(x.value);
  EXPECT_EQ(names, (std::vector<std::string>{"id", "centre.x", "centre.y", "keys.count", "keys[0]",
                                             "keys[1]", "points[0].x", "points[0].y", "weights[0]",
                                             "weights[1]"}));
  EXPECT_EQ(values, (std::vector<std::string>{"1", "1", "0.1", "2", "7", "16909060", "0.5", "nan",
                                              "-0", "3"}));
  EXPECT_TRUE(e[2].numeric);
  EXPECT_FALSE(e[7].numeric);  // NaN is not a JSON number
}

}  // namespace
}  // namespace calf::container
