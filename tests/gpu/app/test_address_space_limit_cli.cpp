// Renders under an address-space limit (`ulimit -v`, as batch systems set it): each ends in an
// image or in one error that names the limit, never in a signal. Lavapipe does not check every
// allocation of its own, and before util/address_space_limit.h a G-PT render of the Cornell box
// died with SIGSEGV (inside vkCreateDevice or a kernel's compilation) under 14 of the 23 limits
// from 200 to 640 MB, and at 1024x1024 under 800, 900 and 950 MB (lavapipe 22.3, 2 cores).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>

#include "cli_runner.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;

const std::string kScene = std::string(GDPT_SOURCE_DIR) + "/scenes/cornell_box.gltf";

struct LimitedRun {
    bool exited = false;  // false: killed by a signal
    int code = -1;        // exit status, or the signal
    std::string output;
};

class AddressSpaceLimitCli : public test::TempDirTest {
protected:
    // `gdpt render <args> -o out.exr` under `ulimit -v` of `mib` MiB.
    LimitedRun render(std::uint64_t mib, const std::string& args) {
        fs::remove(path("out.exr"));
        fs::remove(path("out.png"));
        // exec all the way, so that a signal reaches pclose as one (a shell would turn it into 128 + n)
        const std::string cmd = "exec bash -c 'ulimit -v " + std::to_string(mib * 1024) + "; exec " +
                                test::gdptBinary() + " render " + kScene + " --quiet " + args + " -o " +
                                path("out.exr") + "' 2>&1";
        FILE* pipe = popen(cmd.c_str(), "r");
        LimitedRun r;
        if (!pipe) return r;
        char buf[512];
        while (std::fgets(buf, sizeof buf, pipe)) r.output += buf;
        const int status = pclose(pipe);
        r.exited = WIFEXITED(status);
        r.code = r.exited ? WEXITSTATUS(status) : WTERMSIG(status);
        return r;
    }

    // Renders under every limit from `from` to `to` MiB in steps of `step`; each must end in an
    // image or in exit 1 with an error that names the limit and leaves no output. Returns how
    // many made an image.
    int sweep(std::uint64_t from, std::uint64_t to, std::uint64_t step, const std::string& args) {
        int images = 0;
        for (std::uint64_t mib = from; mib <= to; mib += step) {
            const LimitedRun r = render(mib, args);
            const std::string where = "under ulimit -v of " + std::to_string(mib) + " MiB: " + r.output;
            EXPECT_TRUE(r.exited) << "killed by signal " << r.code << " " << where;
            if (!r.exited) continue;
            if (r.code == 0) {
                EXPECT_TRUE(fs::exists(path("out.exr"))) << where;
                ++images;
                continue;
            }
            EXPECT_EQ(r.code, 1) << where;
            EXPECT_NE(r.output.find("ulimit -v"), std::string::npos) << where;
            EXPECT_FALSE(fs::exists(path("out.exr"))) << where;
        }
        return images;
    }
};

TEST_F(AddressSpaceLimitCli, EveryLimitEndsInAnImageOrAnErrorThatNamesIt) {
    // What this machine's device needs to start (it grows with lavapipe's threads): the refusal
    // under a limit too low for any render says above how much to go.
    const LimitedRun low = render(300, "--method gpt --spp 1");
    ASSERT_TRUE(low.exited) << low.output;
    ASSERT_EQ(low.code, 1) << low.output;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(low.output, m, std::regex("above ([0-9]+) MiB"))) << low.output;
    const std::uint64_t start = std::stoull(m[1]);
    ASSERT_GE(start, 300u) << low.output;

    // A 256x256 G-PT render from below the driver's own start to well past what it needs (about
    // 500 MiB on 2 cores): failures of the driver's start, refusals before the device and
    // before buffers, and images.
    EXPECT_GE(sweep(200, start + 320, 40, "--method gpt --spp 1"), 1);
    // 1024x1024, where the buffers (about 600 MiB) took the room a kernel's compilation needed.
    EXPECT_GE(sweep(start + 300, start + 800, 100, "--method gpt --spp 1 --width 1024 --height 1024"), 1);
}

}  // namespace
}  // namespace gdpt
