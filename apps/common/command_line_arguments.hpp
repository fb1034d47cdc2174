// The command line as CLI11 should see it. CLI11 reads `--name=` (nothing
// after '=') as `--name` and takes the NEXT argument as its value:
// `--output= --events=ev.csv` wrote a file named "--events=ev.csv" (found by
// the fuzzer, issue 34). Each `--name=` is given to CLI11 as `--name ""`,
// so that the command's own check refuses the empty value, naming the option.
#pragma once

#include <string>
#include <vector>

namespace kanegen::cli {

class CommandLineArguments {
 public:
  CommandLineArguments(int argc, char** argv) {
    for (int i = 0; i < argc; ++i) {
      const std::string a = argv[i];
      if (i > 0 && a.size() > 3 && a.rfind("--", 0) == 0 && a.back() == '=' && a.find('=') == a.size() - 1) {
        strings_.push_back(a.substr(0, a.size() - 1));
        strings_.emplace_back();
      } else {
        strings_.push_back(a);
      }
    }
    for (std::string& s : strings_) pointers_.push_back(s.data());
    pointers_.push_back(nullptr);
  }
  CommandLineArguments(const CommandLineArguments&) = delete;
  CommandLineArguments& operator=(const CommandLineArguments&) = delete;

  int argc() const { return static_cast<int>(strings_.size()); }
  char** argv() { return pointers_.data(); }

 private:
  std::vector<std::string> strings_;
  std::vector<char*> pointers_;
};

}  // namespace kanegen::cli
