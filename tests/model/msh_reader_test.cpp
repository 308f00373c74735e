#include "model/msh_reader.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "common/config_error.h"
#include "model/fingertip_model.h"
#include "tests/model/model_test_util.h"

namespace sedbridge::model {
namespace {

using testing::ReplaceLine;
using testing::ThreeTets;

// Expects ReadMshString to fail at `line` with a message containing `fragment`.
void ExpectMshError(const std::string& text, int line, const std::string& fragment) {
  try {
    ReadMshString(text, "bad.msh");
    FAIL() << "accepted; expected an error at line " << line << " containing '" << fragment << "'";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().file, "bad.msh");
    EXPECT_EQ(e.where().line, line) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(MshReader, ReadsNamesEntitiesNodesAndElements) {
  const MshFile m = ReadMshFile(testing::FixturePath("three_tets.msh"));
  ASSERT_EQ(m.physical_names.size(), 3u);
  EXPECT_EQ(m.PhysicalName(3, 1), "epidermis");
  EXPECT_EQ(m.PhysicalName(3, 4), "bone");
  EXPECT_EQ(m.PhysicalName(2, 4), "");
  EXPECT_EQ(m.physical_names[2].line, 8);
  ASSERT_EQ(m.node_tags.size(), 6u);
  EXPECT_EQ(m.node_positions.col(m.node_index.at(6)), Eigen::Vector3d(0.5, -1, 0.5));
  ASSERT_EQ(m.elements.size(), 3u);
  const MshElement& bone = m.elements[2];
  EXPECT_EQ(bone.tag, 12u);
  EXPECT_EQ(bone.type, 4);
  EXPECT_EQ(bone.entity_tag, 3);
  EXPECT_EQ(bone.line, 39);
  EXPECT_EQ(bone.node_tags, (std::vector<std::size_t>{1, 3, 2, 5}));
  ASSERT_EQ(m.PhysicalTagsOf(bone).size(), 1u);
  EXPECT_EQ(m.PhysicalTagsOf(bone)[0], 4);
}

TEST(MshReader, SkipsUnknownSectionsAndLowerDimensionalElements) {
  std::string text = ThreeTets();
  text = ReplaceLine(text, 33, "4 4 9 12");
  text = ReplaceLine(text, 34, "1 7 1 1\n9 1 2\n3 1 4 1");  // a line element in its own block
  text += "$NodeData\n1\n\"x\"\n$EndNodeData\n";
  const MshFile m = ReadMshString(text, "ok.msh");
  EXPECT_EQ(m.elements.size(), 3u);
  EXPECT_EQ(m.elements[0].line, 37);
}

TEST(MshReader, UndefinedNodeNamesElementAndLine) {
  ExpectMshError(ReplaceLine(ThreeTets(), 35, "10 1 2 4 9"), 35, "element 10 references node 9");
}

TEST(MshReader, ShortElementLineNamesElementAndLine) {
  ExpectMshError(ReplaceLine(ThreeTets(), 37, "11 1 2 3"), 37, "malformed element 11");
}

TEST(MshReader, BadCoordinateNamesLine) {
  ExpectMshError(ReplaceLine(ThreeTets(), 28, "0.3 abc 1"), 28, "got 'abc'");
}

TEST(MshReader, MissingCoordinateNamesNode) {
  ExpectMshError(ReplaceLine(ThreeTets(), 26, "1 0"), 26, "coordinates of node 2");
}

TEST(MshReader, DuplicateNodeTag) {
  ExpectMshError(ReplaceLine(ThreeTets(), 20, "1"), 20, "node 1 is defined twice");
}

TEST(MshReader, DuplicateElementTag) {
  ExpectMshError(ReplaceLine(ThreeTets(), 39, "10 1 3 2 5"), 39, "element 10 is defined twice");
}

TEST(MshReader, ElementCountMismatch) {
  ExpectMshError(ReplaceLine(ThreeTets(), 33, "3 4 10 12"), 33, "announces 4 elements");
}

TEST(MshReader, UnknownElementType) {
  ExpectMshError(ReplaceLine(ThreeTets(), 38, "3 3 99 1"), 38, "unknown Gmsh element type 99");
}

TEST(MshReader, RejectsOldVersionAndBinary) {
  ExpectMshError(ReplaceLine(ThreeTets(), 2, "2.2 0 8"), 2, "unsupported MSH version 2.2");
  ExpectMshError(ReplaceLine(ThreeTets(), 2, "4.1 1 8"), 2, "binary");
}

TEST(MshReader, MalformedPhysicalName) {
  ExpectMshError(ReplaceLine(ThreeTets(), 7, "3 2 dermis"), 7, "malformed physical name");
}

TEST(MshReader, MalformedEntity) {
  ExpectMshError(ReplaceLine(ThreeTets(), 13, "2 0 -1 -1 1 1 1 1 2 3"), 13, "bounding entity count");
}

TEST(MshReader, MissingEndTag) {
  ExpectMshError(ReplaceLine(ThreeTets(), 31, "$End"), 31, "expected '$EndNodes'");
}

TEST(MshReader, TruncatedFile) {
  const std::string text = ThreeTets();
  const std::string cut = text.substr(0, text.find("11 1 2 3 4"));
  ExpectMshError(cut, 36, "unexpected end of file");
}

TEST(MshReader, NotAnMshFile) {
  ExpectMshError("hello\n", 1, "expected a section");
  ExpectMshError("$Nodes\n", 1, "$MeshFormat must come first");
}

TEST(MshReader, MissingFileIsAConfigError) {
  EXPECT_THROW(ReadMshFile("/nonexistent/x.msh"), config::ConfigError);
}

}  // namespace
}  // namespace sedbridge::model

namespace sedbridge::model {
namespace {

// Every single-line corruption and every truncation of the fixture either loads (and
// builds a model) or throws ConfigError: never a crash or another exception type.
TEST(MshReader, CorruptedOrTruncatedInputOnlyEverThrowsConfigError) {
  const std::string text = ThreeTets();
  const int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n'));
  const std::vector<std::string> garbage = {"", "x", "-1", "0", "99999999999999999999", "1 2",
                                            "3 1 4 1 5 9 2 6", "$Nodes", "nan nan nan",
                                            "4000000000 1 1 4000000000"};
  int thrown = 0;
  for (int line = 1; line <= lines; ++line) {
    for (const auto& g : garbage) {
      try {
        const MshFile m = ReadMshString(ReplaceLine(text, line, g), "fuzz.msh");
        BuildFingertipModel(m, DefaultModelDescription("fuzz.msh"));  // must also be safe
      } catch (const config::ConfigError& e) {
        ++thrown;
        EXPECT_GT(e.where().line, 0) << "line " << line << " -> '" << g << "': " << e.what();
      }
    }
  }
  EXPECT_GT(thrown, lines * static_cast<int>(garbage.size()) / 2);
  for (std::size_t cut = 0; cut < text.size(); cut += 7) {
    try {
      ReadMshString(text.substr(0, cut), "fuzz.msh");
    } catch (const config::ConfigError&) {
    }
  }
}

}  // namespace
}  // namespace sedbridge::model
