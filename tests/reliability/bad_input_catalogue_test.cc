// The bad-input catalogue (issue 27): every row of bad_inputs.tsv runs one
// portcal command on a spoiled copy of a fixture and checks the promise made
// to a user who gets the input wrong: the expected exit code (never a crash),
// a message with the expected words (the file, image, option or key at
// fault), and, for a failure, every file as it was and no file left behind.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/test_utils.h"

namespace portcal {
namespace {

namespace fs = std::filesystem;

// One row: id, exit code, '|'-separated words, setup (shell, or "@lock
// FILE": another connection holds FILE's write lock), command (shell, run
// in the case's folder; {portcal} is the binary).
struct CatalogueCase {
  std::string id;
  int exit_code = 0;
  std::vector<std::string> words;
  std::string setup;
  std::string command;
};

// gtest prints a row by its id, not as bytes.
void PrintTo(const CatalogueCase& row, std::ostream* out) { *out << row.id; }

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  return parts;
}

std::vector<CatalogueCase> ReadCatalogue() {
  std::vector<CatalogueCase> cases;
  std::ifstream in(PORTCAL_CATALOGUE_PATH);
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> fields = Split(line, '\t');
    if (fields.size() != 5) {
      ADD_FAILURE() << PORTCAL_CATALOGUE_PATH << ":" << line_number
                    << ": expected 5 tab-separated fields";
      continue;
    }
    CatalogueCase row;
    row.id = fields[0];
    row.exit_code = std::stoi(fields[1]);
    if (fields[2] != "-") row.words = Split(fields[2], '|');
    row.setup = fields[3] == "-" ? "" : fields[3];
    row.command = fields[4];
    cases.push_back(row);
  }
  return cases;
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

// Every file under `dir` with its bytes.
std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const std::string name = fs::relative(entry.path(), dir).string();
    files[name] = entry.is_regular_file() ? testing::ReadFileToString(entry.path()) : "<dir>";
  }
  return files;
}

std::string Differences(const std::map<std::string, std::string>& before,
                        const std::map<std::string, std::string>& after) {
  std::string differences;
  for (const auto& [name, bytes] : after) {
    auto it = before.find(name);
    if (it == before.end())
      differences += " left behind: " + name + ";";
    else if (it->second != bytes)
      differences += " changed: " + name + ";";
  }
  for (const auto& [name, bytes] : before) {
    if (!after.count(name)) differences += " removed: " + name + ";";
  }
  return differences;
}

// Holds a database's write lock while alive, as another stage would.
class WriteLock {
 public:
  explicit WriteLock(const fs::path& path) {
    if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK ||
        sqlite3_exec(db_, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr) != SQLITE_OK) {
      ADD_FAILURE() << "cannot lock " << path;
    }
  }
  ~WriteLock() {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    sqlite3_close(db_);
  }

 private:
  sqlite3* db_ = nullptr;
};

class BadInputCatalogue : public ::testing::TestWithParam<CatalogueCase> {
 protected:
  static void SetUpTestSuite() {
    root_ = new testing::TempDir();
    const std::string command = std::string("bash ") + PORTCAL_FIXTURE_SCRIPT + " " +
                                testing::PortcalBinary() + " " +
                                (root_->path() / "fixture").string();
    const testing::CommandResult made = testing::RunCommand(command);
    ASSERT_EQ(made.exit_code, 0) << made.output;
  }
  static void TearDownTestSuite() {
    delete root_;
    root_ = nullptr;
  }
  static testing::TempDir* root_;
};

testing::TempDir* BadInputCatalogue::root_ = nullptr;

// {as_other_user}: the command run as 'nobody' when the tests run as root,
// for whom a file's missing write permission means nothing.
std::string Expand(const std::string& text) {
  const std::string other_user =
      geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups" : "";
  const std::string board = "--Target.cols 9 --Target.rows 6 --Target.square_size 0.03";
  return Replace(
      Replace(Replace(text, "{portcal}", testing::PortcalBinary()), "{as_other_user}", other_user),
      "{board}", board);
}

TEST_P(BadInputCatalogue, KeepsItsPromise) {
  const CatalogueCase& row = GetParam();
  const fs::path work = root_->path() / "cases" / row.id;
  const fs::path scripts = root_->path() / "scripts" / row.id;
  fs::create_directories(work.parent_path());
  fs::create_directories(scripts);
  fs::copy(root_->path() / "fixture", work, fs::copy_options::recursive);
  fs::permissions(root_->path(), fs::perms::all);
  fs::permissions(work.parent_path(), fs::perms::all);
  fs::permissions(work, fs::perms::all);

  const bool locks = row.setup.rfind("@lock ", 0) == 0;
  if (!locks && !row.setup.empty()) {
    std::ofstream(scripts / "setup.sh") << "set -e\ncd '" << work.string() << "'\n"
                                        << Expand(row.setup) << "\n";
    const testing::CommandResult setup =
        testing::RunCommand("bash " + (scripts / "setup.sh").string());
    ASSERT_EQ(setup.exit_code, 0) << "setup of " << row.id << ": " << setup.output;
  }
  const std::map<std::string, std::string> before = Snapshot(work);
  // After the snapshot: closing any descriptor of a file drops this process's
  // POSIX locks on it, SQLite's among them.
  std::unique_ptr<WriteLock> lock;
  if (locks) lock = std::make_unique<WriteLock>(work / row.setup.substr(6));
  std::ofstream(scripts / "run.sh") << "cd '" << work.string() << "'\n"
                                    << Expand(row.command) << "\n";
  const testing::CommandResult result =
      testing::RunCommand("bash " + (scripts / "run.sh").string());
  lock.reset();

  EXPECT_EQ(result.exit_code, row.exit_code) << row.command << "\n" << result.output;
  for (const std::string& word : row.words) {
    EXPECT_NE(result.output.find(word), std::string::npos)
        << "'" << word << "' not in the message of: " << row.command << "\n"
        << result.output;
  }
  if (row.exit_code != 0) {
    EXPECT_EQ(Differences(before, Snapshot(work)), "") << row.command << "\n" << result.output;
  }
  fs::remove_all(work);
}

INSTANTIATE_TEST_SUITE_P(Rows, BadInputCatalogue, ::testing::ValuesIn(ReadCatalogue()),
                         [](const ::testing::TestParamInfo<CatalogueCase>& info) {
                           return info.param.id;
                         });

}  // namespace
}  // namespace portcal
