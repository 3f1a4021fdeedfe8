#pragma once
// Runs a program with arguments (no shell), capturing stdout, stderr and how it ended.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace fss::test {

struct ProcessResult {
    int exitCode = -1; ///< exit status when the program exited normally
    int signal = 0;    ///< terminating signal, 0 when it exited normally
    std::string out;   ///< everything written to stdout
    std::string err;   ///< everything written to stderr
};

inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream os;
    os << in.rdbuf();
    return os.str();
}

/// Runs \p exe with \p args; stdout/stderr go to files in \p scratch (a unique name per call).
inline ProcessResult runProcess(const std::filesystem::path& exe, const std::vector<std::string>& args,
                                const std::filesystem::path& scratch) {
    static int counter = 0;
    std::filesystem::create_directories(scratch);
    const auto outPath =
        scratch / ("out" + std::to_string(::getpid()) + "_" + std::to_string(counter) + ".txt");
    const auto errPath =
        scratch / ("err" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".txt");
    std::vector<std::string> all{exe.string()};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    pid_t pid = 0;
    ProcessResult r;
    if (posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ) != 0) {
        posix_spawn_file_actions_destroy(&actions);
        r.err = "could not start " + exe.string();
        return r;
    }
    posix_spawn_file_actions_destroy(&actions);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
    r.out = slurp(outPath);
    r.err = slurp(errPath);
    std::filesystem::remove(outPath);
    std::filesystem::remove(errPath);
    return r;
}

/// Number of sentences-ending lines: the error contract is one line, one sentence.
inline int countLines(const std::string& s) {
    int n = 0;
    for (char c : s)
        n += (c == '\n');
    return n;
}

/// The command-line error contract: the program exited (no signal) with a non-zero code and printed exactly
/// one line on stderr that mentions \p mustMention.
inline void expectCleanFailure(const ProcessResult& r, const std::string& mustMention) {
    EXPECT_EQ(r.signal, 0) << "crashed with signal " << r.signal << "; stderr: " << r.err;
    EXPECT_NE(r.exitCode, 0);
    EXPECT_EQ(countLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(mustMention), std::string::npos) << "expected '" << mustMention << "' in: " << r.err;
}

} // namespace fss::test
