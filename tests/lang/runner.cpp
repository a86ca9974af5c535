// Golden-test runner for tests/lang: a .frac file states how to run it and what must come out.
//   // args: render --depth 3 --ascii 8x4   the frac subcommand and options (default: run); FILE goes
//                                           right after the subcommand, or where $FILE stands
//                                           (// args: help eval --set a=$FILE), not at all with
//                                           $NOFILE (// args: help eval $NOFILE)
//   // expect: TEXT                         the next line of stdout (all of stdout must be expected);
//                                           TEXT ending in "..." matches a line that begins with it
//   // expect error: LINE:COL: MESSAGE      a diagnostic "FILE:LINE:COL: error: MESSAGE" on stderr
//                                           (every error on stderr must be expected)
//   // expect stderr: TEXT                  some line of stderr contains TEXT
//   // expect exit: N                       exit status (default 0, or 65 with expected errors)
//   // env: NAME=VALUE                      an environment setting for the command
// Run as `lang_runner FRAC FILE ENGINE`, a command that evaluates (eval, render, mesh, dimension, test,
// run) gets `--engine ENGINE`, unless its args name one; output files under /tmp/frac-lang- then get
// the engine in their name, so that the runs under each engine can go on at once. CMake registers a file
// once per engine (interp, jit, aot and auto by default; `// engines: interp jit` limits it), and once for
// other commands.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace {

std::string read(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream ss(text);
    std::string line;
    while (std::getline(ss, line)) out.push_back(line);
    return out;
}

std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t\r");
    const auto e = s.find_last_not_of(" \t\r");
    return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 3 && argc != 4) {
        std::cerr << "usage: lang_runner FRAC FILE.frac [ENGINE]\n";
        return 2;
    }
    const std::string frac = argv[1], file = argv[2], engine = argc == 4 ? argv[3] : "";
    // The JIT's code cache in the build tree, not the user's: later runs of a test load what earlier
    // ones compiled, so the goldens hold for cached code too.
    setenv("FRAC_CACHE_DIR", FRAC_TEST_CACHE_DIR, /*overwrite=*/0);
    std::string args = "run", env; // env: NAME=VALUE settings for the command
    std::vector<std::string> want_out, want_errors, want_stderr;
    int want_exit = -1;
    for (const std::string& line : lines(read(file))) {
        const auto pos = line.find("// ");
        if (pos == std::string::npos) continue;
        const std::string d = line.substr(pos + 3);
        auto value = [&](const std::string& key) {
            return d.rfind(key, 0) == 0 ? d.substr(key.size()) : std::string();
        };
        if (d.rfind("args:", 0) == 0)
            args = trim(value("args:"));
        else if (d.rfind("env:", 0) == 0)
            env += trim(value("env:")) + " ";
        else if (d.rfind("expect error:", 0) == 0)
            want_errors.push_back(trim(value("expect error:")));
        else if (d.rfind("expect stderr:", 0) == 0)
            want_stderr.push_back(trim(value("expect stderr:")));
        else if (d.rfind("expect exit:", 0) == 0)
            want_exit = std::atoi(value("expect exit:").c_str());
        else if (d.rfind("expect:", 0) == 0)
            want_out.push_back(value("expect:").substr(d.size() > 7 && d[7] == ' ' ? 1 : 0));
    }
    if (want_exit < 0) want_exit = want_errors.empty() ? 0 : 65;

    char out_path[] = "/tmp/frac-lang-out-XXXXXX", err_path[] = "/tmp/frac-lang-err-XXXXXX";
    const int fo = mkstemp(out_path), fe = mkstemp(err_path);
    if (fo < 0 || fe < 0) return 2;
    close(fo);
    close(fe);
    std::string command_line;
    if (const auto at = args.find("$NOFILE"); at != std::string::npos) {
        command_line = args.substr(0, at) + args.substr(at + 7);
    } else if (const auto at = args.find("$FILE"); at != std::string::npos) {
        command_line = args.substr(0, at) + quote(file) + args.substr(at + 5);
    } else {
        const std::string sub = args.substr(0, args.find(' '));
        const std::string rest = args.find(' ') == std::string::npos ? "" : args.substr(args.find(' '));
        command_line = sub + " " + quote(file) + rest;
    }
    if (!engine.empty() && command_line.find("--engine") == std::string::npos) {
        command_line += " --engine " + engine;
        // The engine's own output files, named so in the expectations too.
        auto rename = [&](std::string& text) {
            for (std::size_t at = 0; (at = text.find("/tmp/frac-lang-", at)) != std::string::npos; at += 15)
                text.insert(at + 15, engine + "-");
        };
        rename(command_line);
        for (auto* list : {&want_out, &want_stderr})
            for (std::string& w : *list) rename(w);
    }
    const std::string cmd =
        env + quote(frac) + " " + command_line + " >" + out_path + " 2>" + err_path + " </dev/null";
    const int status = std::system(cmd.c_str());
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    const auto out = lines(read(out_path)), err = lines(read(err_path));
    std::remove(out_path);
    std::remove(err_path);

    int failures = 0;
    auto fail = [&](const std::string& what) {
        ++failures;
        std::cerr << file << ": " << what << "\n";
    };
    if (code != want_exit)
        fail("exit status " + std::to_string(code) + ", expected " + std::to_string(want_exit));
    for (std::size_t i = 0; i < std::max(out.size(), want_out.size()); ++i) {
        const std::string got = i < out.size() ? out[i] : "<nothing>";
        const std::string want = i < want_out.size() ? want_out[i] : "<nothing>";
        const bool prefix = want.size() >= 3 && want.compare(want.size() - 3, 3, "...") == 0;
        if (prefix ? got.rfind(want.substr(0, want.size() - 3), 0) != 0 : got != want)
            fail("stdout line " + std::to_string(i + 1) + ": got '" + got + "', expected '" + want + "'");
    }
    std::size_t error_lines = 0;
    for (const std::string& l : err)
        if (l.find(": error: ") != std::string::npos && l.rfind("frac: error:", 0) != 0) ++error_lines;
    for (const std::string& w : want_errors) {
        bool found = false;
        for (const std::string& l : err)
            found = found || l.find(":" + w.substr(0, w.find(": ")) +
                                    ": error: " + w.substr(w.find(": ") + 2)) != std::string::npos;
        if (!found) fail("missing diagnostic '" + w + "'");
    }
    if (error_lines != want_errors.size())
        fail(std::to_string(error_lines) + " diagnostics on stderr, " + std::to_string(want_errors.size()) +
             " expected");
    for (const std::string& w : want_stderr) {
        bool found = false;
        for (const std::string& l : err) found = found || l.find(w) != std::string::npos;
        if (!found) fail("stderr lacks '" + w + "'");
    }
    if (failures) {
        std::cerr << "--- stdout ---\n";
        for (const auto& l : out) std::cerr << l << "\n";
        std::cerr << "--- stderr ---\n";
        for (const auto& l : err) std::cerr << l << "\n";
    }
    return failures ? 1 : 0;
}
