// docs/quickstart.md's commands are the ones workflows/quickstart.sh runs:
// every portcal and mrcal command of the page stands, as written, in the script, so a
// page that drifts from what runs fails here.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

// Whole commands: continuation lines joined, white space folded.
std::vector<std::string> Commands(const fs::path& path, bool code_blocks_only) {
  std::ifstream file(path);
  EXPECT_TRUE(file) << path;
  std::vector<std::string> commands;
  std::string line, command;
  bool in_code = !code_blocks_only;
  while (std::getline(file, line)) {
    if (code_blocks_only && line.rfind("```", 0) == 0) {
      in_code = !in_code;
      continue;
    }
    if (!in_code) continue;
    std::istringstream words(line);
    std::string word, folded;
    while (words >> word) folded += (folded.empty() ? "" : " ") + word;
    const bool continues = !folded.empty() && folded.back() == '\\';
    if (continues) folded.pop_back();
    command += (command.empty() || folded.empty() ? "" : " ") + folded;
    if (continues) continue;
    while (!command.empty() && command.back() == ' ') command.pop_back();
    if (!command.empty()) commands.push_back(command);
    command.clear();
  }
  return commands;
}

TEST(Quickstart, EveryCommandOfThePageRunsInTheWorkflowScript) {
  const fs::path source = PORTCAL_SOURCE_DIR;
  std::set<std::string> script;
  for (std::string command : Commands(source / "workflows/quickstart.sh", false)) {
    const std::string prefix = "\"$portcal\" ";
    if (command.rfind(prefix, 0) == 0) {
      command = "portcal " + command.substr(prefix.size());
    } else if (command.rfind("mrcal-", 0) != 0) {
      continue;
    }
    const size_t pipe = command.find(" | ");
    script.insert(command.substr(0, pipe));
  }
  int num_page_commands = 0;
  for (const std::string& command : Commands(source / "docs/quickstart.md", true)) {
    if (command.rfind("portcal ", 0) != 0 && command.rfind("mrcal-", 0) != 0) continue;
    ++num_page_commands;
    EXPECT_TRUE(script.count(command.substr(0, command.find(" | "))))
        << "docs/quickstart.md runs a command workflows/quickstart.sh does not: " << command;
  }
  EXPECT_GE(num_page_commands, 8);
}

}  // namespace
