// Tests of Status / Expected and of the error id registry (format/include/calf/format/status.h).
#include "calf/format/status.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

namespace calf {
namespace {

Expected<int> parse_positive(int v) {
  if (v <= 0) return Status(ErrorId::kInvalidArgument, "value " + std::to_string(v) + " <= 0");
  return v;
}

Status twice_positive(int v, int* out) {
  CALF_ASSIGN_OR_RETURN(const int x, parse_positive(v));
  *out = 2 * x;
  return Status::Ok();
}

Status chain(int v) {
  int out = 0;
  CALF_RETURN_IF_ERROR(twice_positive(v, &out).with_context("field 'count'"));
  return Status::Ok();
}

TEST(StatusTest, OkAndErrorValues) {
  EXPECT_TRUE(Status::Ok().ok());
  EXPECT_EQ(Status::Ok().to_string(), "ok");
  const Status s(ErrorId::kDepthValue, "depth -1 at pixel (3, 4)");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.number(), 21);
  EXPECT_EQ(s.kind(), ErrorKind::kCorrupt);
  EXPECT_EQ(s.to_string(), "CALF-E021 depth -1 at pixel (3, 4)");
}

TEST(StatusTest, MacrosPropagateAndContextPrefixes) {
  int out = 0;
  EXPECT_TRUE(twice_positive(4, &out).ok());
  EXPECT_EQ(out, 8);
  const Status s = chain(-2).with_context("clip.calf");
  EXPECT_EQ(s.to_string(), "CALF-E001 clip.calf: field 'count': value -2 <= 0");
  EXPECT_TRUE(chain(3).ok());
}

TEST(StatusTest, ExpectedHoldsValueOrStatus) {
  Expected<std::string> a = std::string("x");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(*a, "x");
  EXPECT_TRUE(a.status().ok());
  Expected<std::string> b(ErrorId::kFileOpen, "a.exr: no such file");
  EXPECT_FALSE(b.ok());
  EXPECT_EQ(b.status().id(), ErrorId::kFileOpen);
  EXPECT_EQ(std::move(b).with_context("capture").status().message(),
            "capture: a.exr: no such file");
}

// Every id in CALF_ERROR_LIST is unique, has a summary and a kind, and is documented in
// docs/ERRORS.md as "CALF-Ennn".
TEST(StatusTest, EveryErrorIdIsUniqueAndDocumented) {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  ASSERT_NE(root, nullptr) << "CALF_SOURCE_DIR is set by ctest";
  std::ifstream in(std::string(root) + "/docs/ERRORS.md");
  ASSERT_TRUE(in.good()) << "docs/ERRORS.md is missing";
  std::stringstream doc;
  doc << in.rdbuf();
  // The list as data, so the checks are one loop (an assertion per id per macro expansion made
  // this file take minutes to compile under the sanitizers).
  struct Entry {
    ErrorId id;
    int number;
    const char* name;
  };
  static const Entry kEntries[] = {
#define CALF_ERROR_ENTRY(name, number, kind, summary) {ErrorId::name, number, #name},
      CALF_ERROR_LIST(CALF_ERROR_ENTRY)
#undef CALF_ERROR_ENTRY
  };
  std::set<int> numbers;
  for (const Entry& e : kEntries) {
    EXPECT_TRUE(numbers.insert(e.number).second) << "duplicate id " << e.number;
    EXPECT_EQ(static_cast<int>(e.id), e.number);
    EXPECT_NE(std::string(error_summary(e.id)), "") << e.name;
    EXPECT_NE(doc.str().find(error_code_string(e.id)), std::string::npos)
        << error_code_string(e.id) << " (" << e.name << ") is not documented in docs/ERRORS.md";
  }
  EXPECT_FALSE(numbers.empty());
}

}  // namespace
}  // namespace calf
