// `vdmsim run --export-mesh`: the VTK XML writer on a tiny mesh (structure and values), then
// the binary on the liver: the files read back with meshio (python3-meshio) hold the surface
// and `displacement` = positions - rest positions, mesh.pvd lists every frame with its time,
// two runs give the same bytes, a resumed run the same files as an uninterrupted one, and a
// scene without stress exports what it has and says so in run.json; the elastic core's scene
// draws and exports every stress quantity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/run/mesh_export.hpp"
#include "app/run/vtk_xml.hpp"
#include "app/simulation/prepared_scene.hpp"
#include "support/binary.hpp"
#include "support/scratch_dir.hpp"

namespace fs = std::filesystem;
using vdmsim::test::run_cli;

namespace {

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string vtu_name(int f) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.vtu", f);
  return name;
}

// The liver, its base held, a spot on top pressed down from t = 0 on: frame 0 is the rest
// shape, every later frame deforms. `effects` as the scene lists them.
std::string write_scene(const fs::path& dir, const std::string& effects, int frames) {
  const fs::path scene = dir / "press.yaml";
  std::ofstream(scene) << "name: press\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                       << "/assets/meshes/liver_L4.obj\n"
                          "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                          "  prescribed: [{sphere: {center: [0.035, 0, 0.06], radius: 0.015}, translate: [0, 0, -0.012], "
                          "t: [0, 0.3]}]\n"
                          "simulation: {frames: "
                       << frames << ", dt: 0.05, effects: [" << effects << "]}\n";
  return scene.string();
}

// A python3 that has meshio ("" when none): the one on PATH, else Debian's, where
// python3-meshio installs (a PATH python3 may be another installation, e.g. pyenv's).
std::string python_with_meshio() {
  for (const char* py : {"python3", "/usr/bin/python3"})
    if (run_cli(py, "-c 'import meshio' ").code == 0) return py;
  return "";
}

// Reads each .vtu with meshio and mesh.pvd with an XML parser; one line per file:
//   file <points> <triangles> <cell blocks> <displacement components> <same triangles as rest>
//        <max |points - rest - displacement|> <max |u_i|> <max magnitude or -1> <names...>
// then `dataset <timestep> <file>` per entry of the .pvd.
const char* const kReadBack = R"(import sys, meshio, numpy as np, xml.etree.ElementTree as ET
rest = np.loadtxt(sys.argv[1]).reshape(-1, 3)
tris = np.loadtxt(sys.argv[2], dtype=np.int64).reshape(-1, 3)
for path in sys.argv[4:]:
    m = meshio.read(path)
    t = m.cells_dict.get("triangle", np.zeros((0, 3)))
    u = m.point_data["displacement"]
    err = np.abs(m.points - rest - u).max()
    mag = m.point_data["magnitude"].max() if "magnitude" in m.point_data else -1.0
    print("file", len(m.points), len(t), len(m.cells), u.shape[1], int(np.array_equal(t, tris)), repr(float(err)),
          repr(float(np.linalg.norm(u, axis=1).max())), repr(float(mag)), " ".join(sorted(m.point_data)))
for d in ET.parse(sys.argv[3]).getroot().iter("DataSet"):
    print("dataset", d.get("timestep"), d.get("file"))
)";

struct FileReadBack {
  long points = 0, triangles = 0, blocks = 0, components = 0, same_triangles = 0;
  double rest_error = 1, max_u = 0, max_magnitude = 0;
  std::string names;
};

// The last row of metrics.csv, as numbers (empty cells as 0).
std::vector<double> last_metrics_row(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::vector<double> cells;
  std::stringstream ss(last);
  std::string c;
  while (std::getline(ss, c, ',')) cells.push_back(c.empty() ? 0.0 : std::atof(c.c_str()));
  return cells;
}

}  // namespace

// The writer on two triangles: structure, values (shortest round-trip text) and cell types.
TEST(VtkXml, WritesATriangleSurfaceWithPointDataAsPlainText) {
  vdm::NodeMat x(4, 3), u(4, 3);
  x << 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0.1, 0.1, -2.5e-7;
  u << 0, 0, 0, 0.5, 0, 0, 0, 1e-3, 0, 0, 0, -2.5e-7;
  vdm::TriMat tris(2, 3);
  tris << 0, 1, 2, 1, 3, 2;
  const std::vector<float> p{0.f, 1.5f, 0.1f, -3e4f};
  const std::string v = vdmsim::vtu_text(x, tris, {{"displacement", &u}}, {{"contact_pressure", &p}});
  EXPECT_EQ(v.rfind("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\"", 0), 0u) << v;
  EXPECT_NE(v.find("<Piece NumberOfPoints=\"4\" NumberOfCells=\"2\">"), std::string::npos) << v;
  EXPECT_NE(v.find("<PointData Vectors=\"displacement\">"), std::string::npos);
  EXPECT_NE(v.find("<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n"
                   "          0 0 0\n          0.5 0 0\n          0 0.001 0\n          0 0 -2.5e-07\n"
                   "        </DataArray>"),
            std::string::npos)
      << v;
  EXPECT_NE(v.find("<DataArray type=\"Float32\" Name=\"contact_pressure\" format=\"ascii\">\n"
                   "          0\n          1.5\n          0.1\n          -30000\n        </DataArray>"),
            std::string::npos)
      << v;
  EXPECT_NE(v.find("<Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n"
                   "          0 0 0\n          0.1 0 0\n          0 0.1 0\n          0.1 0.1 -2.5e-07\n"),
            std::string::npos)
      << v;
  EXPECT_NE(v.find("Name=\"connectivity\" format=\"ascii\">\n          0 1 2\n          1 3 2\n"), std::string::npos) << v;
  EXPECT_NE(v.find("Name=\"offsets\" format=\"ascii\">\n          3\n          6\n"), std::string::npos) << v;
  EXPECT_NE(v.find("Name=\"types\" format=\"ascii\">\n          5\n          5\n        </DataArray>"), std::string::npos)
      << v;
  EXPECT_EQ(count(v, "<DataArray"), count(v, "</DataArray>"));
  EXPECT_EQ(count(v, "<DataArray"), 6);
  const std::string tail = "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  EXPECT_EQ(v.substr(v.size() - tail.size()), tail);

  const std::string pvd = vdmsim::pvd_text({{0.05, "mesh/frame_00000.vtu"}, {0.1, "mesh/frame_00001.vtu"}});
  EXPECT_EQ(pvd,
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
            "  <Collection>\n"
            "    <DataSet timestep=\"0.05\" group=\"\" part=\"0\" file=\"mesh/frame_00000.vtu\"/>\n"
            "    <DataSet timestep=\"0.1\" group=\"\" part=\"0\" file=\"mesh/frame_00001.vtu\"/>\n"
            "  </Collection>\n</VTKFile>\n");
}

// The scalars are the stress view's quantities but `displacement` (the vector's name), and
// without stress only those that need none.
TEST(MeshExport, ExportsTheStressViewsQuantitiesThatTheModelComputes) {
  std::vector<std::string> all, plain;
  for (render::Quantity q : vdmsim::exported_scalars(true)) all.push_back(render::to_string(q));
  for (render::Quantity q : vdmsim::exported_scalars(false)) plain.push_back(render::to_string(q));
  EXPECT_EQ(all, (std::vector<std::string>{"magnitude", "stress_x", "stress_y", "stress_z", "contact_pressure",
                                           "volumetric_strain"}));
  EXPECT_EQ(plain, std::vector<std::string>{"contact_pressure"});
  std::vector<std::string> names = render::quantity_names();
  EXPECT_EQ(names.size(), all.size() + 1);  // + displacement
}

TEST(MeshExport, FilesReadBackWithMeshioAndTwoRunsGiveTheSameBytes) {
  const fs::path dir = vdmsim::test::scratch_dir("mesh_export") / "e2e";
  fs::create_directories(dir / "one" / "mesh");
  const int frames = 4;
  const std::string scene = write_scene(dir, "stress", frames);
  // Left by an earlier run: a stale frame goes, a file of the user's stays.
  std::ofstream(dir / "one" / "mesh" / "frame_00099.vtu") << "stale";
  std::ofstream(dir / "one" / "mesh" / "notes.txt") << "mine";
  for (const char* run : {"one", "two"}) {
    const auto r = run_cli(VDMSIM_BINARY, "run " + scene + " --out " + (dir / run).string() + " --export-mesh --no-render");
    ASSERT_EQ(r.code, 0) << r.output;
  }
  const fs::path one = dir / "one";
  EXPECT_FALSE(fs::exists(one / "mesh" / "frame_00099.vtu"));
  EXPECT_TRUE(fs::exists(one / "mesh" / "notes.txt"));
  const std::string js = read_file(one / "run.json");
  EXPECT_NE(js.find("\"mesh_export\": {\"frames\": 4, \"pvd\": \"mesh.pvd\", \"point_data\": [\"displacement\", "
                    "\"magnitude\", \"stress_x\", \"stress_y\", \"stress_z\", \"contact_pressure\", "
                    "\"volumetric_strain\"]}"),
            std::string::npos)
      << js;
  // Determinism: the same scene twice, the same bytes.
  for (int f = 0; f < frames; ++f)
    EXPECT_EQ(read_file(one / "mesh" / vtu_name(f)), read_file(dir / "two" / "mesh" / vtu_name(f))) << vtu_name(f);
  EXPECT_EQ(read_file(one / "mesh.pvd"), read_file(dir / "two" / "mesh.pvd"));

  const std::string py = python_with_meshio();
  if (py.empty()) GTEST_SKIP() << "python3 with meshio not found (apt-get install python3-meshio): files not read back";
  // The rest surface as the run has it, for the script.
  vdmsim::PreparedScene ps;
  std::vector<vdmsim::SceneProblem> problems;
  ASSERT_TRUE(vdmsim::prepare_scene(scene, ps, problems));
  const vdm::SurfaceMesh& rest = ps.organ().model.rest;
  {
    std::ofstream pts(dir / "rest.txt"), tris(dir / "tris.txt");
    pts.precision(17);
    pts << rest.positions << "\n";
    tris << rest.triangles << "\n";
  }
  std::ofstream(dir / "read_back.py") << kReadBack;
  const auto r = run_cli(py, (dir / "read_back.py").string() + " " + (dir / "rest.txt").string() + " " +
                                 (dir / "tris.txt").string() + " " + (one / "mesh.pvd").string() + " " +
                                 (one / "mesh" / vtu_name(0)).string() + " " +
                                 (one / "mesh" / vtu_name(frames - 1)).string());
  ASSERT_EQ(r.code, 0) << r.output;
  std::stringstream lines(r.output);
  std::vector<FileReadBack> files;
  std::vector<std::pair<double, std::string>> datasets;
  std::string kind;
  while (lines >> kind) {
    if (kind == "file") {
      FileReadBack b;
      lines >> b.points >> b.triangles >> b.blocks >> b.components >> b.same_triangles >> b.rest_error >> b.max_u >>
          b.max_magnitude;
      std::getline(lines, b.names);
      files.push_back(b);
    } else if (kind == "dataset") {
      std::pair<double, std::string> d;
      lines >> d.first >> d.second;
      datasets.push_back(d);
    } else {
      FAIL() << "unexpected output:\n" << r.output;
    }
  }
  ASSERT_EQ(files.size(), 2u) << r.output;
  for (const FileReadBack& b : files) {
    EXPECT_EQ(b.points, rest.node_count());
    EXPECT_EQ(b.triangles, rest.triangle_count());
    EXPECT_EQ(b.blocks, 1);
    EXPECT_EQ(b.components, 3);
    EXPECT_EQ(b.same_triangles, 1);
    EXPECT_LT(b.rest_error, 1e-15) << "displacement is not positions - rest positions";
    EXPECT_EQ(b.names, " contact_pressure displacement magnitude stress_x stress_y stress_z volumetric_strain");
  }
  EXPECT_LT(files[0].max_u, 1e-12) << "frame 0 is the scene at t = 0, before the press";
  EXPECT_GT(files[1].max_u, 1e-4) << "the organ should be pressed by the last frame";
  // The last frame's values are the run's: metrics.csv's max displacement and max stress.
  const std::vector<double> row = last_metrics_row(one / "metrics.csv");
  ASSERT_GE(row.size(), 16u);
  EXPECT_NEAR(files[1].max_u, row[14], 1e-8 * row[14]);
  EXPECT_NEAR(files[1].max_magnitude, row[15], 1e-6 * row[15]);
  ASSERT_EQ(datasets.size(), size_t(frames)) << r.output;
  for (int f = 0; f < frames; ++f) {
    EXPECT_EQ(datasets[f].second, "mesh/" + vtu_name(f));
    EXPECT_DOUBLE_EQ(datasets[f].first, f * 0.05);  // frame f is the scene at f dt
  }
}

// Without the stress effect: displacement and contact_pressure, and run.json says why. A
// later run without --export-mesh removes the export (it would be stale).
TEST(MeshExport, WithoutStressExportsWhatThereIsAndSaysSo) {
  const fs::path dir = vdmsim::test::scratch_dir("mesh_export") / "no_stress";
  fs::create_directories(dir);
  const std::string scene = write_scene(dir, "", 2);
  const fs::path out = dir / "out";
  auto r = run_cli(VDMSIM_BINARY, "run " + scene + " --out " + out.string() + " --export-mesh --no-render");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string js = read_file(out / "run.json");
  EXPECT_NE(js.find("\"mesh_export\": {\"frames\": 2, \"pvd\": \"mesh.pvd\", \"point_data\": [\"displacement\", "
                    "\"contact_pressure\"], \"stress_quantities\": \"not exported: the scene computes no stress"),
            std::string::npos)
      << js;
  const std::string vtu = read_file(out / "mesh" / vtu_name(1));
  EXPECT_NE(vtu.find("Name=\"contact_pressure\""), std::string::npos);
  EXPECT_EQ(vtu.find("Name=\"magnitude\""), std::string::npos);

  r = run_cli(VDMSIM_BINARY, "run " + scene + " --out " + out.string() + " --no-render");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(read_file(out / "run.json").find("\"mesh_export\": null"), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "mesh.pvd"));
  EXPECT_FALSE(fs::exists(out / "mesh" / vtu_name(0)));
}

// The values of a .vtu's point-data array `name` (the writer's plain text).
std::vector<double> vtu_array(const std::string& vtu, const std::string& name) {
  std::vector<double> out;
  const size_t at = vtu.find("Name=\"" + name + "\"");
  if (at == std::string::npos) return out;
  const size_t begin = vtu.find('>', at) + 1, end = vtu.find('<', begin);
  std::stringstream ss(vtu.substr(begin, end - begin));
  double v;
  while (ss >> v) out.push_back(v);
  return out;
}

// organ.model vdm_core with the stress effect: the stress view draws every quantity, and the
// export holds every stress quantity, finite, the pressed organ's stress nonzero and
// metrics.csv's max_stress_pa the exported magnitude's largest value.
TEST(MeshExport, TheCoreRendersAndExportsEveryStressQuantity) {
  const fs::path dir = vdmsim::test::scratch_dir("mesh_export") / "core";
  fs::create_directories(dir);
  const int frames = 3;
  auto scene_with = [&](const std::string& quantity) {
    const fs::path scene = dir / ("core_" + quantity + ".yaml");
    std::ofstream(scene) << "name: core\norgan:\n  mesh: " << VDMSIM_SOURCE_DIR
                         << "/assets/meshes/liver_L4.obj\n"
                            "  model: vdm_core\n  cell_size: 0.01\n  material: {young_modulus: 3000, density: 1060}\n"
                            "  fixed: [{box: {min: [-0.3, -0.2, -0.2], max: [0.3, 0.2, -0.03]}}]\n"
                            "  prescribed: [{sphere: {center: [0.035, 0, 0.06], radius: 0.015}, translate: [0, 0, -0.012], "
                            "t: [0, 0.1]}]\n"
                            "simulation: {frames: "
                         << frames
                         << ", dt: 0.05, effects: [stress]}\n"
                            "render: {width: 96, height: 64, hud: false, views: [shaded, stress], stress: {quantity: "
                         << quantity << "}}\n";
    return scene.string();
  };
  for (const std::string& q : render::quantity_names()) {
    const fs::path out = dir / q;
    const std::string extra = q == "magnitude" ? " --export-mesh" : "";
    const auto r = run_cli(VDMSIM_BINARY, "run " + scene_with(q) + " --out " + out.string() + extra);
    ASSERT_EQ(r.code, 0) << q << ":\n" << r.output;
    EXPECT_TRUE(fs::exists(out / "stress" / "stress_00002.png")) << q;
    EXPECT_TRUE(fs::exists(out / "frames" / "frame_00002.png")) << q;
  }
  const fs::path out = dir / "magnitude";
  const std::string js = read_file(out / "run.json");
  EXPECT_NE(js.find("\"point_data\": [\"displacement\", \"magnitude\", \"stress_x\", \"stress_y\", \"stress_z\", "
                    "\"contact_pressure\", \"volumetric_strain\"]}"),
            std::string::npos)
      << js;
  const std::string vtu = read_file(out / "mesh" / vtu_name(frames - 1));
  for (const render::Quantity quantity : vdmsim::exported_scalars(true)) {
    const std::string q = render::to_string(quantity);
    const std::vector<double> v = vtu_array(vtu, q);
    ASSERT_FALSE(v.empty()) << q;
    double largest = 0;
    for (double x : v) {
      ASSERT_TRUE(std::isfinite(x)) << q;
      largest = std::max(largest, std::abs(x));
    }
    EXPECT_GT(largest, 0.0) << q << ": the pressed organ's field is zero";
  }
  const std::vector<double> magnitude = vtu_array(vtu, "magnitude");
  const std::vector<double> row = last_metrics_row(out / "metrics.csv");
  ASSERT_GE(row.size(), 16u);
  EXPECT_NEAR(*std::max_element(magnitude.begin(), magnitude.end()), row[15], 1e-6 * row[15]);
}

// Ctrl-C, then --resume: the frames written stay, the new ones are appended, and the files
// and mesh.pvd equal an uninterrupted run's.
TEST(MeshExport, AResumedRunGivesTheFilesOfAnUninterruptedOne) {
  const fs::path dir = vdmsim::test::scratch_dir("mesh_export") / "resume";
  fs::create_directories(dir);
  const int frames = 60;
  const std::string scene = write_scene(dir, "stress", frames);
  const fs::path whole = dir / "whole", resumed = dir / "resumed";
  const std::string args = " --export-mesh --no-render --frames " + std::to_string(frames);
  auto r = run_cli(VDMSIM_BINARY, "run " + scene + " --out " + whole.string() + args);
  ASSERT_EQ(r.code, 0) << r.output;

  const pid_t pid = vdmsim::test::spawn_quiet({VDMSIM_BINARY, "run", scene, "--out", resumed.string(), "--export-mesh",
                                               "--no-render", "--frames", std::to_string(frames)});
  ASSERT_NE(pid, 0);
  const int code = vdmsim::test::interrupt_once_exists(pid, resumed / "mesh" / vtu_name(5), 120);
  if (code == 0) GTEST_SKIP() << "the run finished before it could be interrupted";
  ASSERT_EQ(code, 130);
  // Resuming without the flag would leave the frames after the interruption without files.
  r = run_cli(VDMSIM_BINARY, "run " + scene + " --out " + resumed.string() + " --resume --no-render --frames " +
                                 std::to_string(frames));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--export-mesh"), std::string::npos) << r.output;

  r = run_cli(VDMSIM_BINARY, "run " + scene + " --out " + resumed.string() + " --resume" + args);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(read_file(resumed / "run.json").find("\"resumed_from_frame\""), std::string::npos);
  for (int f = 0; f < frames; ++f)
    EXPECT_EQ(read_file(whole / "mesh" / vtu_name(f)), read_file(resumed / "mesh" / vtu_name(f))) << vtu_name(f);
  EXPECT_EQ(read_file(whole / "mesh.pvd"), read_file(resumed / "mesh.pvd"));
  EXPECT_EQ(count(read_file(resumed / "mesh.pvd"), "<DataSet "), frames);
}
