#include "core/opensim/marker_set.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "core/errors.h"
#include "tests/support/test_data.h"
#include "tests/support/test_helpers.h"

namespace mmm::opensim {
namespace {

using ::testing::HasSubstr;

using test::io_error_of;

// <OpenSimDocument><MarkerSet><objects> around `markers`; the first marker
// element starts on line 4.
std::string marker_set(const std::string& markers) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<OpenSimDocument Version=\"40000\">\n"
         "<MarkerSet name=\"set\"><objects>\n" +
         markers + "\n</objects></MarkerSet>\n</OpenSimDocument>\n";
}

// <InverseKinematicsTool><IKTaskSet> around `tasks`.
std::string ik_setup(const std::string& tasks) {
  return "<OpenSimDocument Version=\"30000\">\n<InverseKinematicsTool name=\"s\">\n"
         "<IKTaskSet name=\"t\"><objects>\n" +
         tasks + "\n</objects></IKTaskSet>\n</InverseKinematicsTool>\n</OpenSimDocument>\n";
}

// --- Small documents ------------------------------------------------------

TEST(MarkerSetTest, ReadsOpenSim3And4Markers) {
  const std::vector<MarkerDefinition> markers = parse_marker_set(
      marker_set("<Marker name=\"R.ASIS\"><socket_parent_frame>/bodyset/pelvis"
                 "</socket_parent_frame><location>0.02 0.03 0.128</location>"
                 "<fixed>true</fixed></Marker>\n"
                 "<Marker name=\"Sternum\"><body> torso </body>"
                 "<location>  0.07\n 0.3 -0 </location></Marker>\n"
                 "<Marker name=\"Lab\"><socket_parent_frame>/ground</socket_parent_frame>"
                 "<location>1 2 3</location><fixed> FALSE </fixed></Marker>"),
      "set.xml");
  ASSERT_EQ(markers.size(), 3U);
  EXPECT_EQ(markers[0].name, "R.ASIS");
  EXPECT_EQ(markers[0].body, "pelvis");
  EXPECT_EQ(markers[0].location, Eigen::Vector3d(0.02, 0.03, 0.128));
  EXPECT_TRUE(markers[0].fixed);
  EXPECT_EQ(markers[1].body, "torso");
  EXPECT_EQ(markers[1].location, Eigen::Vector3d(0.07, 0.3, 0.0));
  EXPECT_FALSE(markers[1].fixed);  // absent: false
  EXPECT_EQ(markers[2].body, "ground");
  EXPECT_FALSE(markers[2].fixed);
}

TEST(MarkerSetTest, ReadsTheMarkerSetOfAModel) {
  const std::vector<MarkerDefinition> markers = parse_marker_set(
      "<OpenSimDocument Version=\"40000\"><Model name=\"m\"><MarkerSet><objects>"
      "<Marker name=\"A\"><socket_parent_frame>/bodyset/femur_r</socket_parent_frame>"
      "<location>0 -0.4 0</location></Marker></objects></MarkerSet></Model></OpenSimDocument>",
      "model.osim");
  ASSERT_EQ(markers.size(), 1U);
  EXPECT_EQ(markers[0].body, "femur_r");
}

TEST(MarkerSetTest, ReadsIkMarkerWeights) {
  const std::map<std::string, IkMarkerWeight> weights = parse_ik_task_weights(
      ik_setup("<IKMarkerTask name=\"R.ASIS\"><apply>true</apply><weight>10</weight>"
               "</IKMarkerTask>\n"
               "<IKMarkerTask name=\"Top.Head\"><apply>false</apply><weight>0.1</weight>"
               "</IKMarkerTask>\n"
               "<IKMarkerTask name=\"Sternum\"/>\n"
               "<IKCoordinateTask name=\"knee_angle_r\"><weight>1000</weight>"
               "</IKCoordinateTask>"),
      "setup.xml");
  ASSERT_EQ(weights.size(), 3U);  // the coordinate task is not a marker
  EXPECT_TRUE(weights.at("R.ASIS").apply);
  EXPECT_EQ(weights.at("R.ASIS").weight, 10.0);
  EXPECT_FALSE(weights.at("Top.Head").apply);
  EXPECT_EQ(weights.at("Top.Head").weight, 0.1);
  EXPECT_TRUE(weights.at("Sternum").apply);  // OpenSim's defaults
  EXPECT_EQ(weights.at("Sternum").weight, 1.0);
}

TEST(MarkerSetTest, FollowsATaskSetFileReference) {
  test::ScratchDir scratch("ik-tasks");
  test::write_file(scratch / "tasks.xml",
                   "<OpenSimDocument Version=\"30000\"><IKTaskSet><objects>"
                   "<IKMarkerTask name=\"L.Heel\"><weight>2</weight></IKMarkerTask>"
                   "</objects></IKTaskSet></OpenSimDocument>");
  test::write_file(scratch / "setup.xml",
                   "<OpenSimDocument Version=\"30000\"><InverseKinematicsTool>"
                   "<IKTaskSet file=\"tasks.xml\"/></InverseKinematicsTool></OpenSimDocument>");
  const std::map<std::string, IkMarkerWeight> weights = read_ik_task_weights(scratch / "setup.xml");
  ASSERT_EQ(weights.size(), 1U);
  EXPECT_EQ(weights.at("L.Heel").weight, 2.0);
}

// --- Malformed input: each error names the line and the element ------------

TEST(MarkerSetTest, RejectsMalformedXml) {
  // tinyxml2 names the line of the element left open (<MarkerSet>, line 2).
  const std::string message = io_error_of([] {
    (void)parse_marker_set("<OpenSimDocument>\n<MarkerSet>\n</OpenSimDocument>", "broken.xml");
  });
  EXPECT_THAT(message, HasSubstr("broken.xml: line 2: malformed XML"));
}

TEST(MarkerSetTest, RejectsADocumentWithoutAMarkerSet) {
  EXPECT_THAT(io_error_of([] {
                (void)parse_marker_set("<OpenSimDocument><Model/></OpenSimDocument>", "x.xml");
              }),
              HasSubstr("no <MarkerSet> found under <OpenSimDocument>"));
}

TEST(MarkerSetTest, RejectsAMarkerWithoutLocationOrBody) {
  EXPECT_THAT(io_error_of([] {
                (void)parse_marker_set(
                    marker_set("<Marker name=\"A\"><body>pelvis</body></Marker>"), "x.xml");
              }),
              HasSubstr("line 4: <Marker name=\"A\">: no <location>"));
  EXPECT_THAT(io_error_of([] {
                (void)parse_marker_set(
                    marker_set("<Marker name=\"A\"><location>0 0 0</location></Marker>"), "x.xml");
              }),
              HasSubstr("line 4: <Marker name=\"A\">: expected the body the marker sits on"));
}

TEST(MarkerSetTest, RejectsABadLocation) {
  EXPECT_THAT(io_error_of([] {
                (void)parse_marker_set(marker_set("<Marker name=\"A\"><body>pelvis</body>\n"
                                                  "<location>0.1 0.2</location></Marker>"),
                                       "x.xml");
              }),
              HasSubstr("line 5: <location>: expected 3 numbers (x y z in m) in the location "
                        "of 'A', got 2"));
  EXPECT_THAT(io_error_of([] {
                (void)parse_marker_set(marker_set("<Marker name=\"A\"><body>pelvis</body>"
                                                  "<location>0.1 0,2 0</location></Marker>"),
                                       "x.xml");
              }),
              HasSubstr("coordinate 1 of 'A' is '0,2', expected a finite number"));
}

TEST(MarkerSetTest, RejectsABadFixedFlag) {
  EXPECT_THAT(io_error_of([] {
                (void)parse_marker_set(marker_set("<Marker name=\"A\"><body>pelvis</body>"
                                                  "<location>0 0 0</location>"
                                                  "<fixed>yes please</fixed></Marker>"),
                                       "x.xml");
              }),
              HasSubstr("<fixed>: expected true or false, got 'yes please'"));
}

TEST(MarkerSetTest, RejectsDuplicateAndNamelessMarkers) {
  const std::string a = "<Marker name=\"A\"><body>pelvis</body><location>0 0 0</location></Marker>";
  EXPECT_THAT(io_error_of([&] { (void)parse_marker_set(marker_set(a + "\n" + a), "x.xml"); }),
              HasSubstr("line 5: <Marker name=\"A\">: the marker name 'A' is used twice"));
  EXPECT_THAT(io_error_of([] {
                (void)parse_marker_set(
                    marker_set("<Marker><body>pelvis</body><location>0 0 0</location></Marker>"),
                    "x.xml");
              }),
              HasSubstr("the marker has no name attribute"));
}

TEST(MarkerSetTest, RejectsBadIkTasks) {
  EXPECT_THAT(io_error_of([] {
                (void)parse_ik_task_weights(
                    ik_setup("<IKMarkerTask name=\"A\"><weight>-1</weight></IKMarkerTask>"),
                    "setup.xml");
              }),
              HasSubstr("line 4: <weight>: the weight of 'A' is '-1', expected a finite number"));
  EXPECT_THAT(io_error_of([] {
                (void)parse_ik_task_weights(
                    ik_setup("<IKMarkerTask name=\"A\"/>\n<IKMarkerTask name=\"A\"/>"),
                    "setup.xml");
              }),
              HasSubstr("line 5: <IKMarkerTask name=\"A\">: a second task for marker 'A'"));
  EXPECT_THAT(io_error_of([] {
                (void)parse_ik_task_weights("<OpenSimDocument><ScaleTool/></OpenSimDocument>",
                                            "scale.xml");
              }),
              HasSubstr("no <IKTaskSet> found"));
}

TEST(MarkerSetTest, RejectsMissingFiles) {
  EXPECT_THAT(io_error_of([] { (void)read_marker_set(test::gait2392_pipelines() / "absent.xml"); }),
              HasSubstr("absent.xml: no such file"));
  EXPECT_THAT(
      io_error_of([] { (void)read_ik_task_weights(test::gait2392_pipelines() / "absent_ik.xml"); }),
      HasSubstr("absent_ik.xml: no such file"));
}

// --- Real data -------------------------------------------------------------

TEST(MarkerSetTest, ReadsTheGait2392ScaleMarkerSet) {
  const std::vector<MarkerDefinition> markers =
      read_marker_set(test::gait2392_pipelines() / "gait2392_Scale_MarkerSet.xml");
  ASSERT_EQ(markers.size(), 39U);
  EXPECT_EQ(markers.front().name, "Sternum");
  EXPECT_EQ(markers.front().body, "torso");
  const std::set<std::string> bodies = {"torso",   "pelvis",  "femur_r", "femur_l",
                                        "tibia_r", "tibia_l", "calcn_r", "calcn_l"};
  std::map<std::string, int> per_body;
  for (const MarkerDefinition& marker : markers) {
    EXPECT_TRUE(bodies.count(marker.body) == 1) << marker.name << " on " << marker.body;
    ++per_body[marker.body];
    EXPECT_FALSE(marker.fixed) << marker.name;
    // Locations are in m: every marker is within 1 m of its body origin (the
    // farthest, Top.Head, is 0.66 m above the torso's); in mm they would not be.
    EXPECT_LT(marker.location.norm(), 1.0) << marker.name;
  }
  EXPECT_EQ(per_body["pelvis"], 3);
  EXPECT_EQ(per_body["calcn_r"], 6);
  const auto asis = std::find_if(markers.begin(), markers.end(),
                                 [](const MarkerDefinition& m) { return m.name == "R.ASIS"; });
  ASSERT_NE(asis, markers.end());
  EXPECT_EQ(asis->body, "pelvis");
  EXPECT_EQ(asis->location, Eigen::Vector3d(0.02, 0.03, 0.128));
}

TEST(MarkerSetTest, ReadsTheSubjectIkWeights) {
  const std::map<std::string, IkMarkerWeight> weights =
      read_ik_task_weights(test::gait2392_pipelines() / "subject01_Setup_IK.xml");
  ASSERT_EQ(weights.size(), 31U);
  EXPECT_EQ(weights.at("R.ASIS").weight, 10.0);
  EXPECT_EQ(weights.at("V.Sacral").weight, 10.0);
  EXPECT_EQ(weights.at("R.Acromium").weight, 0.5);
  EXPECT_EQ(weights.at("Top.Head").weight, 0.1);
  EXPECT_EQ(weights.at("R.Heel").weight, 10.0);
  EXPECT_EQ(weights.at("R.Thigh.Upper").weight, 1.0);
  for (const auto& [name, weight] : weights) EXPECT_TRUE(weight.apply) << name;
}

}  // namespace
}  // namespace mmm::opensim
