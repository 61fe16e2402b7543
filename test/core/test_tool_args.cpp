// The tools' option parser (src/tools/tool_args.h): values, flags, help, and clear errors.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "../../src/tools/tool_args.h"

namespace kct_tools {
namespace {

/// Runs the parser on `args` (argv[0] added).
bool parse(std::vector<std::string> args, const std::vector<ToolOption>& options) {
  args.insert(args.begin(), "tool");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  return parse_tool_options(static_cast<int>(argv.size()), argv.data(), options);
}

std::string error_of(const std::vector<std::string>& args, const std::vector<ToolOption>& options) {
  try {
    parse(args, options);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ToolArgs, StoresValuesAndFlags) {
  std::string model;
  double scale = 1.0;
  int frames = -1;
  long long pixels = 0;
  bool quiet = false;
  const std::vector<ToolOption> options = {{"--model", store(model)},
                                           {"--model-scale", store(scale)},
                                           {"--max-frames", store(frames)},
                                           {"--max-image-pixels", store(pixels)},
                                           flag("--quiet", quiet)};
  EXPECT_TRUE(parse({"--model", "a.obj", "--quiet", "--model-scale", "1e-3", "--max-frames", "12",
                     "--max-image-pixels", "16777216"},
                    options));
  EXPECT_EQ(model, "a.obj");
  EXPECT_DOUBLE_EQ(scale, 1e-3);
  EXPECT_EQ(frames, 12);
  EXPECT_EQ(pixels, 16777216LL);
  EXPECT_TRUE(quiet);
}

TEST(ToolArgs, HelpReturnsFalse) {
  std::string model;
  EXPECT_FALSE(parse({"--model", "a.obj", "-h"}, {{"--model", store(model)}}));
  EXPECT_FALSE(parse({"--help"}, {{"--model", store(model)}}));
}

TEST(ToolArgs, ErrorsNameTheOptionAndWhatIsWrong) {
  std::string model;
  double scale = 1.0;
  int frames = 0;
  const std::vector<ToolOption> options = {
      {"--model", store(model)}, {"--model-scale", store(scale)}, {"--max-frames", store(frames)}};
  EXPECT_EQ(error_of({"--modle", "a.obj"}, options), "unknown option --modle");
  EXPECT_EQ(error_of({"--model"}, options), "--model needs a value");
  EXPECT_EQ(error_of({"--model-scale", "abc"}, options), "--model-scale abc: not a number");
  EXPECT_EQ(error_of({"--model-scale", "1e-3mm"}, options), "--model-scale 1e-3mm: not a number");
  EXPECT_EQ(error_of({"--max-frames", "2.5"}, options), "--max-frames 2.5: not a number");
  EXPECT_EQ(error_of({"--max-frames", "99999999999"}, options),
            "--max-frames 99999999999: out of range");
}

TEST(ToolArgs, CustomSetterErrorsAreReported) {
  const std::vector<ToolOption> options = {{"--param", [](const std::string& kv) {
                                              if (kv.find('=') == std::string::npos)
                                                throw std::invalid_argument("takes NAME=VALUE");
                                            }}};
  EXPECT_TRUE(parse({"--param", "a=1"}, options));
  EXPECT_EQ(error_of({"--param", "a"}, options), "--param a: takes NAME=VALUE");
}

}  // namespace
}  // namespace kct_tools
