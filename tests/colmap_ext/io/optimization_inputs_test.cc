// Reading mrcal's optimization_inputs: base 85 and .npz archives as Python
// and NumPy write them (checked against their own output), hostile archives
// refused by name, and a two-camera solve written by mrcal's Python read
// as one camera's board views.
#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/io/mrcal_model.h"
#include "colmap_ext/io/mrcal_optimization_inputs.h"
#include "colmap_ext/io/npz_archive.h"
#include "colmap_ext/io/npz_reader.h"
#include "colmap_ext/util/error.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

namespace fs = std::filesystem;

bool HavePythonModules(const std::string& modules) {
  return testing::RunCommand("/usr/bin/python3 -c 'import " + modules + "' 2>&1").exit_code == 0;
}

std::vector<double> Numbers(const std::string& line) {
  std::istringstream in(line);
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  return values;
}

std::string ExpectInputError(const std::function<void()>& read) {
  try {
    read();
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

// Values from Python's base64.b85encode; every byte value round-trips.
TEST(NpzReader, Base85DecodesWhatPythonEncodes) {
  EXPECT_EQ(DecodeBase85("", "t"), "");
  EXPECT_EQ(DecodeBase85("Xa", "t"), "h");
  EXPECT_EQ(DecodeBase85("Xk~0{Zv", "t"), "hello");
  EXPECT_EQ(DecodeBase85("|Ni~_`}z", "t"), "\xff\xfe\xfd\xfc\xfb\xfa");
  std::string all;
  for (int i = 0; i < 256; ++i) all += static_cast<char>(i);
  for (size_t n = 0; n < 9; ++n)
    EXPECT_EQ(DecodeBase85(EncodeBase85(all.substr(n)), "t"), all.substr(n));
  EXPECT_NE(ExpectInputError([] {
              DecodeBase85("Xk\"0{", "model.cameramodel");
            }).find("model.cameramodel: byte 2"),
            std::string::npos);
  EXPECT_NE(ExpectInputError([] { DecodeBase85("~~~~~", "t"); }).find("overflows"),
            std::string::npos);
}

TEST(NpzReader, ReadsPortcalsOwnArchive) {
  NpzArchive npz;
  npz.AddDoubles("m", {2, 3}, {1, 2, 3, 4, 5, 6.5});
  npz.AddInt32s("i", {0, 6}, {});
  npz.AddBool("b", true);
  npz.AddString("none", "");
  npz.AddStrings("names", {"a.png", "image_10.png"});
  const std::map<std::string, NpyArray> arrays = ReadNpz(npz.Bytes(), "t");
  ASSERT_EQ(arrays.size(), 5u);
  EXPECT_EQ(arrays.at("m").shape, (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(arrays.at("m").Doubles("t"), (std::vector<double>{1, 2, 3, 4, 5, 6.5}));
  EXPECT_EQ(arrays.at("i").size(), 0);
  EXPECT_EQ(arrays.at("b").Integers("t"), std::vector<int64_t>{1});
  EXPECT_TRUE(arrays.at("none").IsNone());
  EXPECT_FALSE(arrays.at("names").IsNone());
  EXPECT_EQ(arrays.at("names").Strings("t"), (std::vector<std::string>{"a.png", "image_10.png"}));
}

// NumPy's own output: Fortran order, 64-bit and 32-bit types, a 0-d
// boolean, a format 2.0 header.
TEST(NpzReader, ReadsWhatNumpyWrites) {
  if (!HavePythonModules("numpy")) GTEST_SKIP() << "numpy is not importable by /usr/bin/python3";
  testing::TempDir dir;
  const fs::path path = dir / "a.npz";
  const fs::path script = dir / "write.py";
  std::ofstream(script) << R"(import io, sys, zipfile, numpy as np
a = np.arange(24.0).reshape(2, 3, 4)
np.savez_compressed(sys.argv[1], f=np.asfortranarray(a), i8=np.array([-3, 2**40]), f4=np.float32([0.5]),
                    b=np.bool_(False), u=np.uint8([7]), s='LENSMODEL_OPENCV4')
v2 = io.BytesIO()
np.lib.format.write_array(v2, np.array([[1.5, 2.5]]), version=(2, 0))
with zipfile.ZipFile(sys.argv[1], 'a') as z:
    z.writestr('v2.npy', v2.getvalue())
)";
  const auto run =
      testing::RunCommand("/usr/bin/python3 " + script.string() + " " + path.string() + " 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::map<std::string, NpyArray> arrays = ReadNpz(testing::ReadFileToString(path), "t");
  std::vector<double> c_order(24);
  for (int i = 0; i < 24; ++i) c_order[i] = i;
  EXPECT_EQ(arrays.at("f").Doubles("t"), c_order) << "Fortran order read as C order";
  EXPECT_EQ(arrays.at("i8").Integers("t"), (std::vector<int64_t>{-3, int64_t{1} << 40}));
  EXPECT_EQ(arrays.at("f4").Doubles("t"), std::vector<double>{0.5});
  EXPECT_EQ(arrays.at("b").Doubles("t"), std::vector<double>{0});
  EXPECT_EQ(arrays.at("u").Integers("t"), std::vector<int64_t>{7});
  EXPECT_EQ(arrays.at("s").Strings("t"), std::vector<std::string>{"LENSMODEL_OPENCV4"});
  EXPECT_EQ(arrays.at("v2").shape, (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(arrays.at("v2").Doubles("t"), (std::vector<double>{1.5, 2.5}));
  EXPECT_NE(ExpectInputError([&] { arrays.at("s").Doubles("s"); }).find("strings where numbers"),
            std::string::npos);
  EXPECT_NE(ExpectInputError([&] { arrays.at("f").Integers("f"); }).find("where integers"),
            std::string::npos);
}

// Pickled objects, archives inflating past the bound, damaged bytes and
// headers that do not match their data: each an InputError naming the
// source, none a crash.
TEST(NpzReader, RefusesHostileArchives) {
  if (!HavePythonModules("numpy")) GTEST_SKIP() << "numpy is not importable by /usr/bin/python3";
  testing::TempDir dir;
  const fs::path script = dir / "hostile.py";
  std::ofstream(script) << R"(import zipfile, numpy as np
np.savez('pickle.npz', o=np.array([{'a': 1}], dtype=object))
with zipfile.ZipFile('bomb.npz', 'w', zipfile.ZIP_DEFLATED) as z:
    z.writestr('x.npy', b'\x93NUMPY' + bytes(300 << 20))
header = b"{'descr': '<f8', 'fortran_order': False, 'shape': (1000000, 1000000), }\n"
with zipfile.ZipFile('shape.npz', 'w') as z:
    z.writestr('x.npy', b'\x93NUMPY\x01\x00' + bytes([len(header), 0]) + header + bytes(16))
)";
  const auto run = testing::RunCommand("cd " + dir.path().string() + " && /usr/bin/python3 " +
                                       script.string() + " 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(ExpectInputError([&] {
              ReadNpz(testing::ReadFileToString(dir / "pickle.npz"), "p.cameramodel");
            }).find("p.cameramodel: 'o': array type '|O' is not read"),
            std::string::npos);
  EXPECT_NE(ExpectInputError([&] {
              ReadNpz(testing::ReadFileToString(dir / "bomb.npz"), "b");
            }).find("more than 256 MiB"),
            std::string::npos);

  NpzArchive npz;
  npz.AddDoubles("m", {2, 3}, {1, 2, 3, 4, 5, 6.5});
  const std::string good = npz.Bytes();
  EXPECT_NE(ExpectInputError([&] {
              ReadNpz(good.substr(0, good.size() / 2), "half");
            }).find("half: not a zip"),
            std::string::npos);
  for (size_t at = 0; at < good.size();
       ++at) {  // every byte flipped: an error or the same values, never a crash
    std::string damaged = good;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x5a);
    try {
      const auto arrays = ReadNpz(damaged, "d");
      if (arrays.count("m")) arrays.at("m").Doubles("d");
    } catch (const InputError&) {
    }
  }
  EXPECT_NE(ExpectInputError([&] {
              ReadNpz(testing::ReadFileToString(dir / "shape.npz"), "s");
            }).find("shape larger than its data"),
            std::string::npos);
}

// mrcal's Python writes a two-camera solve (NumPy's serialisation, the
// second camera posed by its extrinsics); camera 1's board views come back
// posed in that camera's frame, as mrcal.compose_rt composes them, with the
// weights, the warp, what was optimised and the image paths.
TEST(MrcalOptimizationInputs, ReadsOneCameraOfMrcalsTwoCameraSolve) {
  if (!HavePythonModules("numpy, mrcal"))
    GTEST_SKIP() << "numpy and mrcal are not importable by /usr/bin/python3";
  testing::TempDir dir;
  const fs::path script = dir / "solve.py";
  std::ofstream(script) << R"(import sys, numpy as np, mrcal
rng = np.random.default_rng(1)
frames = rng.normal(size=(2, 6)) * 0.3
frames[:, 5] += 1
ext = np.array([[0.1, -0.2, 0.05, 0.3, 0.01, -0.02]])
obs = np.zeros((4, 3, 4, 3))
obs[..., 0] = rng.uniform(0, 640, (4, 3, 4))
obs[..., 1] = rng.uniform(0, 480, (4, 3, 4))
obs[..., 2] = 1.0
obs[3, 0, 0, 2] = -1
idx = np.array([[0, 0, -1], [0, 1, 0], [1, 0, -1], [1, 1, 0]], dtype=np.int32)
intr = np.array([[500, 500, 320, 240, 0, 0, 0, 0], [510, 505, 321, 239, 0.01, 0, 0, 0]], float)
oi = dict(intrinsics=intr, extrinsics_rt_fromref=ext, frames_rt_toref=frames, points=None,
          observations_board=obs, indices_frame_camintrinsics_camextrinsics=idx, observations_point=None,
          indices_point_camintrinsics_camextrinsics=None, lensmodel='LENSMODEL_OPENCV4',
          imagersizes=np.array([[640, 480], [640, 480]], dtype=np.int32),
          calobject_warp=np.array([0.001, -0.002]), do_optimize_intrinsics_core=True,
          do_optimize_intrinsics_distortions=False, do_optimize_extrinsics=True, do_optimize_frames=True,
          do_optimize_calobject_warp=True, calibration_object_spacing=0.05, do_apply_outlier_rejection=True,
          do_apply_regularization=True, verbose=False, imagepaths=np.array(['a0.png', 'a1.png', 'b0.png', 'b1.png']))
mrcal.cameramodel(optimization_inputs=oi, icam_intrinsics=1).write(sys.argv[1])
for f in (0, 1):
    print(' '.join('%.17g' % v for v in mrcal.compose_rt(ext[0], frames[f])))
print(' '.join('%.17g' % v for v in obs[3].ravel()))
)";
  const fs::path model_path = dir / "two.cameramodel";
  const auto run = testing::RunCommand("/usr/bin/python3 " + script.string() + " " +
                                       model_path.string() + " 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::istringstream lines(run.output);
  std::string line;
  std::vector<std::vector<double>> expected;
  while (std::getline(lines, line)) expected.push_back(Numbers(line));
  ASSERT_EQ(expected.size(), 3u) << run.output;

  const MrcalCameraModelFile file = ReadMrcalCameraModel(model_path);
  EXPECT_EQ(file.icam_intrinsics, 1);
  const MrcalBoardSolve solve = ReadMrcalBoardSolve(file, model_path.string());
  EXPECT_EQ(solve.width_n, 4);
  EXPECT_EQ(solve.height_n, 3);
  EXPECT_DOUBLE_EQ(solve.spacing, 0.05);
  ASSERT_EQ(solve.frames_rt_toref.size(), 2u);
  for (int f = 0; f < 2; ++f) {
    for (int k = 0; k < 6; ++k)
      EXPECT_NEAR(solve.frames_rt_toref[f][k], expected[f][k], 1e-12) << f << " " << k;
  }
  ASSERT_EQ(solve.observations.size(), 2u * 36);
  for (size_t k = 0; k < 36; ++k) EXPECT_EQ(solve.observations[36 + k], expected[2][k]) << k;
  EXPECT_EQ(solve.image_paths, (std::vector<std::string>{"a1.png", "b1.png"}));
  EXPECT_TRUE(solve.warp_estimated);
  EXPECT_DOUBLE_EQ(solve.calobject_warp.y(), -0.002);
  EXPECT_TRUE(solve.intrinsics_core_estimated);
  EXPECT_FALSE(solve.intrinsics_distortions_estimated);
}

// A model without a solve, and one whose solve is damaged: the lens still
// reads; the solve is refused naming the file.
TEST(MrcalOptimizationInputs, MissingOrDamagedSolveNamesTheFile) {
  testing::TempDir dir;
  Camera camera = Camera::FromModelName("OPENCV", 500, 640, 480);
  WriteMrcalCameraModel(camera, Rigid3d(), dir / "lens.cameramodel");
  const MrcalCameraModelFile lens = ReadMrcalCameraModel(dir / "lens.cameramodel");
  EXPECT_NE(ExpectInputError([&] {
              ReadMrcalBoardSolve(lens, "lens.cameramodel");
            }).find("lens.cameramodel: carries no optimization_inputs"),
            std::string::npos);
  MrcalBoardSolve solve;
  solve.width_n = 2;
  solve.height_n = 2;
  solve.spacing = 0.1;
  solve.frames_rt_toref = {{0, 0, 0, 0, 0, 1}};
  solve.observations = {1, 1, 1, 2, 1, 1, 1, 2, 1, 2, 2, 1};
  WriteMrcalCameraModel(camera, Rigid3d(), dir / "solve.cameramodel", &solve);
  std::string text = testing::ReadFileToString(dir / "solve.cameramodel");
  const size_t start = text.find("'optimization_inputs': b'") + 25;
  const size_t at = (start + text.find('\'', start)) / 2;  // inside the deflated data
  text[at] = text[at] == 'A' ? 'B' : 'A';
  std::ofstream(dir / "damaged.cameramodel") << text;
  const MrcalCameraModelFile damaged = ReadMrcalCameraModel(dir / "damaged.cameramodel");
  EXPECT_EQ(damaged.camera.params, lens.camera.params);
  EXPECT_NE(ExpectInputError([&] {
              ReadMrcalBoardSolve(damaged, "damaged.cameramodel");
            }).find("damaged.cameramodel"),
            std::string::npos);
  const MrcalBoardSolve back =
      ReadMrcalBoardSolve(ReadMrcalCameraModel(dir / "solve.cameramodel"), "s");
  EXPECT_EQ(back.observations, solve.observations);
  EXPECT_EQ(back.frames_rt_toref, solve.frames_rt_toref);
}

}  // namespace
}  // namespace portcal

namespace portcal {
namespace {

// Image names in any script survive the archive (NumPy's '<U' is UTF-32):
// a name that is not UTF-8 (Latin-1 bytes) is kept with U+FFFD, as
// Python's errors='replace'.
TEST(NpzReader, NamesInAnyScriptRoundTrip) {
  NpzArchive npz;
  npz.AddStrings("names", {"café.png", "水中/カメラ 01.png", "plain.png", "lat\xe9in.png"});
  const std::vector<std::string> back = ReadNpz(npz.Bytes(), "t").at("names").Strings("t");
  EXPECT_EQ(back, (std::vector<std::string>{"café.png", "水中/カメラ 01.png", "plain.png",
                                            "lat\xef\xbf\xbdin.png"}));
}

}  // namespace
}  // namespace portcal
