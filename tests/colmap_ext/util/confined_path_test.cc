// Names from data stay inside their folder: '..', absolute paths, control
// characters, symbolic links leaving the folder and special files refused
// by name; nested names and links inside the folder allowed. Output files
// that are an input or a device refused.
#include "colmap_ext/util/confined_path.h"

#include <gtest/gtest.h>

#include <fstream>

#include "colmap_ext/util/error.h"
#include "tests/test_utils.h"

namespace portcal {
namespace {

namespace fs = std::filesystem;

std::string Refusal(const fs::path& folder, const std::string& name) {
  try {
    ConfinedPath(folder, name, "image name in test.db");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(ConfinedPath, NamesStayInsideTheFolder) {
  testing::TempDir dir;
  fs::create_directories(dir / "images/cam1");
  fs::create_directories(dir / "outside");
  std::ofstream(dir / "images/cam1/a.png") << "x";
  EXPECT_EQ(ConfinedPath(dir / "images", "cam1/a.png", "n"), dir / "images/cam1/a.png");
  EXPECT_EQ(ConfinedPath(dir / "images", "cam1/new.png", "n"), dir / "images/cam1/new.png");
  EXPECT_EQ(ConfinedPath(dir / "images", "./cam1/a.png", "n"), dir / "images/./cam1/a.png");

  EXPECT_NE(Refusal(dir / "images", "../outside/secret.png")
                .find("image name in test.db '../outside/secret.png' climbs out"),
            std::string::npos);
  EXPECT_NE(Refusal(dir / "images", "cam1/../../x.png").find("climbs out"), std::string::npos);
  EXPECT_NE(Refusal(dir / "images", "/etc/passwd").find("is absolute"), std::string::npos);
  EXPECT_NE(Refusal(dir / "images", "a\nb.png").find("'a?b.png' holds a control character"),
            std::string::npos);
  EXPECT_NE(Refusal(dir / "images", "").find("is empty"), std::string::npos);

  fs::create_directory_symlink(dir / "outside", dir / "images/link");
  EXPECT_NE(
      Refusal(dir / "images", "link/secret.png").find("leaves the folder through a symbolic link"),
      std::string::npos);
  fs::create_directory_symlink(dir / "images/cam1", dir / "images/inner");
  EXPECT_EQ(ConfinedPath(dir / "images", "inner/a.png", "n"), dir / "images/inner/a.png");
  fs::create_directories(dir / "images/folder.png");
  EXPECT_NE(Refusal(dir / "images", "folder.png").find("not a regular file"), std::string::npos);
}

TEST(ConfinedPath, OutputFilesAreNewRegularFiles) {
  testing::TempDir dir;
  std::ofstream(dir / "in.db") << "x";
  fs::create_symlink(dir / "in.db", dir / "alias.db");
  EXPECT_NO_THROW(
      CheckOutputFile("--output_path", (dir / "out.txt").string(), {(dir / "in.db").string()}));
  EXPECT_THROW(
      CheckOutputFile("--output_path", (dir / "alias.db").string(), {(dir / "in.db").string()}),
      OptionError);
  EXPECT_THROW(CheckOutputFile("--output_path", "/dev/null", {}), OptionError);
  EXPECT_THROW(CheckOutputFile("--output_path", dir.path().string(), {}), OptionError);
}

}  // namespace
}  // namespace portcal
