#include "core/volumetric/labelled_lattice.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/errors.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/primitives.h"
#include "tests/support/test_data.h"

namespace mmm::volumetric {
namespace {

using Eigen::Vector3d;
using mesh::IndexedMesh;

std::int64_t count(const LabelledLattice& lattice, std::uint16_t label) {
  return std::ranges::count(lattice.label, label);
}

TEST(LabelledLatticeTest, ASphereKeepsItsVolume) {
  const double r = 20.0;
  const IndexedMesh sphere = mesh::make_icosphere(5, r);
  const LabelledLattice lattice =
      build_labelled_lattice({{"ball", &sphere}}, {}, {.spacing_mm = 2.0});
  const double exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const MuscleCells& ball = lattice.muscles.at(0);
  EXPECT_NEAR(ball.segmented_mm3 / exact, 1.0, 0.01);  // the icosphere's own facets
  EXPECT_NEAR(ball.kept_mm3 / ball.segmented_mm3, 1.0, 0.01);
  EXPECT_DOUBLE_EQ(ball.kept_mm3, ball.inside_mm3);
  EXPECT_EQ(ball.to_bones_mm3, 0.0);
  EXPECT_EQ(ball.to_muscles_mm3, 0.0);
  EXPECT_DOUBLE_EQ(ball.kept_mm3, static_cast<double>(count(lattice, 1)) * 8.0);
  // A cell is labelled exactly when its centre is inside the sphere (up to
  // the facets' sagitta, about 0.03 mm at this resolution).
  for (int k = 0; k < lattice.cells.z(); ++k) {
    for (int j = 0; j < lattice.cells.y(); ++j) {
      for (int i = 0; i < lattice.cells.x(); ++i) {
        const double d = lattice.centre(i, j, k).norm();
        if (std::abs(d - r) < 0.1) continue;
        ASSERT_EQ(lattice.at(i, j, k), d < r ? 1 : 0) << i << " " << j << " " << k;
      }
    }
  }
}

// Depth inside an axis-aligned box (distance to its surface), for the
// analytic cases.
double box_depth(const Vector3d& x, const Vector3d& lo, const Vector3d& hi) {
  return std::min((x - lo).minCoeff(), (hi - x).minCoeff());
}
bool in_box(const Vector3d& x, const Vector3d& lo, const Vector3d& hi) {
  return (x.array() > lo.array()).all() && (x.array() < hi.array()).all();
}

// Two boxes overlapping by 6 mm along x, b wider than a. Without regrowth,
// each cell of the overlap goes to the box it is deeper in (along the
// middle, x = 30, away from a's sides; b's near them), nothing is lost from
// the union, and what each lost is the other's gain.
TEST(LabelledLatticeTest, AnOverlapGoesToTheDeeperMuscle) {
  const Vector3d a_lo(0.0, 0.0, 0.0), a_hi(33.0, 30.0, 30.0);
  const Vector3d b_lo(27.0, -5.0, -5.0), b_hi(60.0, 35.0, 35.0);
  const IndexedMesh a = mesh::make_box(a_lo, a_hi);
  const IndexedMesh b = mesh::make_box(b_lo, b_hi);
  const LabelledLattice lattice = build_labelled_lattice(
      {{"a", &a}, {"b", &b}}, {}, {.spacing_mm = 1.0, .max_regrowth_mm = 0.0});
  const MuscleCells& ca = lattice.muscles[0];
  const MuscleCells& cb = lattice.muscles[1];
  EXPECT_NEAR(ca.segmented_mm3, 33.0 * 900.0, 1e-6);
  EXPECT_NEAR(ca.inside_mm3, 33.0 * 900.0, 1e-6);
  EXPECT_NEAR(ca.kept_mm3 + cb.kept_mm3, 33.0 * 900.0 + 33.0 * 1600.0 - 6.0 * 900.0, 1e-6);
  EXPECT_NEAR(ca.kept_mm3, ca.inside_mm3 - ca.to_muscles_mm3, 1e-6);
  EXPECT_NEAR(cb.kept_mm3, cb.inside_mm3 - cb.to_muscles_mm3, 1e-6);
  EXPECT_NEAR(ca.to_muscles_mm3 + cb.to_muscles_mm3, 6.0 * 900.0, 1e-6);
  EXPECT_EQ(ca.regrown_mm3, 0.0);
  for (int k = 0; k < lattice.cells.z(); ++k) {
    for (int j = 0; j < lattice.cells.y(); ++j) {
      for (int i = 0; i < lattice.cells.x(); ++i) {
        const Vector3d c = lattice.centre(i, j, k);
        const bool ina = in_box(c, a_lo, a_hi);
        const bool inb = in_box(c, b_lo, b_hi);
        int expected = ina ? 1 : inb ? 2 : 0;
        if (ina && inb) {
          const double da = box_depth(c, a_lo, a_hi);
          const double db = box_depth(c, b_lo, b_hi);
          if (std::abs(da - db) < 1e-6) continue;  // a tie: either
          expected = da > db ? 1 : 2;
        }
        ASSERT_EQ(lattice.at(i, j, k), expected) << c.transpose();
      }
    }
  }
  // Along the middle of a, the overlap is split at x = 30.
  for (int i = 0; i < lattice.cells.x(); ++i) {
    const Vector3d c = lattice.centre(i, 20, 20);
    ASSERT_NEAR(c.y(), 14.5, 1e-9);
    if (c.x() > 27.0 && c.x() < 33.0) {
      EXPECT_EQ(lattice.at(i, 20, 20), c.x() < 30.0 ? 1 : 2);
    }
  }
}

// With regrowth (the default) a muscle that gave cells to another grows the
// same volume back into the free cells next to it, nearest its surface
// first: a layer on its free sides, and nothing into the other muscle.
TEST(LabelledLatticeTest, LostVolumeGrowsBackOnTheFreeSides) {
  const Vector3d a_lo(0.0, 0.0, 0.0), a_hi(33.0, 30.0, 30.0);
  const Vector3d b_lo(27.0, 0.0, 0.0), b_hi(60.0, 30.0, 30.0);
  const IndexedMesh a = mesh::make_box(a_lo, a_hi);
  const IndexedMesh b = mesh::make_box(b_lo, b_hi);
  const LabelledLattice lattice =
      build_labelled_lattice({{"a", &a}, {"b", &b}}, {}, {.spacing_mm = 1.0});
  for (const MuscleCells& m : lattice.muscles) {
    EXPECT_NEAR(m.kept_mm3, m.segmented_mm3, 0.5) << m.name;  // within a cell
    EXPECT_NEAR(m.regrown_mm3, m.to_muscles_mm3, 0.5) << m.name;
    EXPECT_LE(m.regrowth_depth_mm, 1.0) << m.name;  // one layer of 1 mm cells is enough
  }
  // The regrown cells lie outside both boxes, within one cell of them.
  int grown = 0;
  for (int k = 0; k < lattice.cells.z(); ++k) {
    for (int j = 0; j < lattice.cells.y(); ++j) {
      for (int i = 0; i < lattice.cells.x(); ++i) {
        const Vector3d c = lattice.centre(i, j, k);
        if (lattice.at(i, j, k) == 0 || in_box(c, a_lo, a_hi) || in_box(c, b_lo, b_hi)) continue;
        ++grown;
        const Vector3d lo(0.0, 0.0, 0.0), hi(60.0, 30.0, 30.0);
        EXPECT_GT(box_depth(c, lo - Vector3d::Constant(1.0), hi + Vector3d::Constant(1.0)), 0.0);
      }
    }
  }
  EXPECT_NEAR(grown, 6 * 900, 2);
}

TEST(LabelledLatticeTest, TheResultDoesNotDependOnTheThreads) {
  const IndexedMesh a = mesh::make_icosphere(4, 15.0, {0.0, 0.0, 0.0});
  const IndexedMesh b = mesh::make_icosphere(4, 12.0, {20.0, 3.0, -2.0});
  const IndexedMesh c = mesh::make_icosphere(4, 10.0, {8.0, -14.0, 5.0});
  const std::vector<NamedSurface> muscles = {{"a", &a}, {"b", &b}, {"c", &c}};
  const LabelledLattice one =
      build_labelled_lattice(muscles, {}, {.spacing_mm = 1.5, .threads = 1});
  const LabelledLattice four =
      build_labelled_lattice(muscles, {}, {.spacing_mm = 1.5, .threads = 4});
  EXPECT_EQ(one.label, four.label);
  for (std::size_t m = 0; m < 3; ++m) {
    EXPECT_EQ(one.muscles[m].kept_mm3, four.muscles[m].kept_mm3);
    const MuscleCells& cells = one.muscles[m];
    EXPECT_NEAR(cells.inside_mm3 - cells.to_muscles_mm3 + cells.regrown_mm3, cells.kept_mm3, 1e-6);
  }
}

TEST(LabelledLatticeTest, BonesAreCarvedOut) {
  const IndexedMesh muscle = mesh::make_box({-20.0, -20.0, 0.0}, {20.0, 20.0, 60.0});
  IndexedMesh bone = mesh::make_cylinder(8.0, 80.0, 64);
  bone.V.col(2).array() -= 10.0;  // through the muscle from end to end
  const LabelledLattice lattice = build_labelled_lattice(
      {{"around", &muscle}}, {{"shaft", &bone}}, {.spacing_mm = 1.0, .max_regrowth_mm = 0.0});
  const MuscleCells& m = lattice.muscles[0];
  // Cell centres (half-integers here) inside the 64-gon, between its
  // inscribed and circumscribed circles, times the 60 layers.
  int inner = 0;
  int outer = 0;
  const double r_in = 8.0 * std::cos(std::numbers::pi / 64.0);
  for (int j = 0; j < lattice.cells.y(); ++j) {
    for (int i = 0; i < lattice.cells.x(); ++i) {
      const double r = lattice.centre(i, j, 0).head<2>().norm();
      inner += r < r_in ? 1 : 0;
      outer += r < 8.0 ? 1 : 0;
    }
  }
  EXPECT_GE(m.to_bones_mm3, 60.0 * inner);
  EXPECT_LE(m.to_bones_mm3, 60.0 * outer);
  EXPECT_NEAR(m.kept_mm3, m.inside_mm3 - m.to_bones_mm3, 1e-6);
  EXPECT_EQ(m.to_muscles_mm3, 0.0);
  for (int k = 0; k < lattice.cells.z(); ++k) {
    const Vector3d c = lattice.centre(lattice.cells.x() / 2, lattice.cells.y() / 2, k);
    if (c.z() > 1.0 && c.z() < 59.0) {
      EXPECT_EQ(lattice.at(lattice.cells.x() / 2, lattice.cells.y() / 2, k), 0) << "axis " << c.z();
    }
  }
}

TEST(LabelledLatticeTest, BadInputIsRefusedWithItsName) {
  const IndexedMesh ok = mesh::make_icosphere(2, 5.0);
  IndexedMesh inward = ok;
  inward.F.col(1).swap(inward.F.col(2));
  IndexedMesh broken = ok;
  broken.V(3, 1) = std::nan("");
  const auto message = [](const auto& call) {
    try {
      call();
    } catch (const InvalidInputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { build_labelled_lattice({}, {}); }).find("no muscles"), std::string::npos);
  EXPECT_NE(message([&] {
              build_labelled_lattice({{"m", &ok}}, {}, {.spacing_mm = 0.0});
            }).find("spacing_mm"),
            std::string::npos);
  EXPECT_NE(message([&] {
              build_labelled_lattice({{"m", &ok}}, {}, {.spacing_mm = NAN});
            }).find("spacing_mm"),
            std::string::npos);
  EXPECT_NE(message([&] {
              build_labelled_lattice({{"m", &ok}}, {}, {.padding_cells = 0});
            }).find("padding_cells"),
            std::string::npos);
  EXPECT_NE(message([&] {
              build_labelled_lattice({{"m", &ok}}, {}, {.max_regrowth_mm = -1.0});
            }).find("max_regrowth_mm"),
            std::string::npos);
  EXPECT_NE(message([&] {
              build_labelled_lattice({{"flipped", &inward}}, {});
            }).find("muscle 'flipped'"),
            std::string::npos);
  EXPECT_NE(message([&] {
              build_labelled_lattice({{"m", &ok}}, {{"nan", &broken}});
            }).find("bone 'nan'"),
            std::string::npos);
  EXPECT_NE(message([&] {
              build_labelled_lattice({{"none", nullptr}}, {});
            }).find("'none'"),
            std::string::npos);
  EXPECT_NE(message([&] {
              build_labelled_lattice({{"m", &ok}}, {}, {.spacing_mm = 0.01, .max_cells = 1000});
            }).find("larger spacing"),
            std::string::npos);
}

// The Visible Human Female's vastus intermedius runs into her femur (as
// registered from another scan) by 4-5 % of its volume, and her posterior
// thigh muscles touch each other. At 2 mm, bone carved out and volume grown
// back, each keeps its volume within 2 %.
TEST(LabelledLatticeRealDataTest, ThighMusclesKeepTheirVolumeWithinTwoPercent) {
  const std::filesystem::path dir = test::data_dir() / "vhf" / "Right";
  const std::vector<std::string> names = {"VastusIntermedius", "AdductorMagnus", "Semimembranosus",
                                          "Semitendonosus", "BicepsFemorisShortHead"};
  std::vector<IndexedMesh> surfaces;
  surfaces.reserve(names.size());
  for (const std::string& name : names) {
    surfaces.push_back(mesh::read_mesh(dir / ("VHF_Right_Muscle_" + name + "_smooth.stl")));
  }
  const IndexedMesh femur = mesh::read_mesh(test::data_dir() / "vhf" / "registered" /
                                            "VHF_Right_Bone_Femur_registered.stl");
  std::vector<NamedSurface> muscles;
  for (std::size_t m = 0; m < names.size(); ++m) muscles.push_back({names[m], &surfaces[m]});
  const LabelledLattice lattice =
      build_labelled_lattice(muscles, {{"femur", &femur}}, {.spacing_mm = 2.0, .threads = 2});
  for (const MuscleCells& m : lattice.muscles) {
    EXPECT_LT(std::abs(m.change()), 0.02)
        << m.name << ": " << m.segmented_mm3 << " -> " << m.kept_mm3 << " mm^3 (bone "
        << m.to_bones_mm3 << ", muscles " << m.to_muscles_mm3 << ", regrown " << m.regrown_mm3
        << ")";
  }
  const MuscleCells& vi = lattice.muscles[0];
  EXPECT_GT(vi.to_bones_mm3, 0.03 * vi.segmented_mm3);  // the overlap with the femur is there
  EXPECT_NEAR(vi.regrown_mm3,
              vi.to_bones_mm3 + vi.to_muscles_mm3 - (vi.inside_mm3 - vi.segmented_mm3), 8.0 * 2.0);
}

}  // namespace
}  // namespace mmm::volumetric
