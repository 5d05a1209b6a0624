#include "launch/supervisor.hpp"

#include "runtime/process.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>

namespace adit::launch {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Seconds as a Clock duration (steady_clock arithmetic with duration<double> yields a different time_point type).
Clock::duration seconds(double s) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); }

namespace {

struct Child {
  ProcessSpec spec;
  pid_t pid = -1;
  int fd = -1;  // read end of the child's stdout+stderr
  std::string partial;
  std::ofstream log;
  double backoff_s = 1.0;
  Clock::time_point started, next_start;
  bool finished = false;  // exited and will not be restarted
};

void say(const std::string& line) {
  std::fprintf(stdout, "[launch] %s\n", line.c_str());
  std::fflush(stdout);
}

std::string resolve(const std::string& program, const std::string& bin_dir) {
  if (program.find('/') == std::string::npos && (program == "adit" || program.rfind("adit-", 0) == 0)) {
    const fs::path candidate = fs::path(bin_dir) / program;
    if (fs::exists(candidate)) return candidate.string();
  }
  return program;
}

bool start(Child& c, const LaunchSpec& spec, const SupervisorOptions& options) {
  int fds[2];
  if (::pipe(fds) != 0) return false;
  const pid_t pid = ::fork();
  if (pid < 0) return false;
  if (pid == 0) {
    ::setpgid(0, 0);  // own process group: the terminal's Ctrl-C reaches only the supervisor, which stops us in order
    ::dup2(fds[1], STDOUT_FILENO);
    ::dup2(fds[1], STDERR_FILENO);
    ::close(fds[0]);
    ::close(fds[1]);
    if (!spec.lcm_url.empty()) ::setenv("LCM_DEFAULT_URL", spec.lcm_url.c_str(), 1);
    // adit's own programs first, also for commands run through a shell.
    const char* path = std::getenv("PATH");
    ::setenv("PATH", (options.bin_dir + ":" + (path ? path : "/usr/bin:/bin")).c_str(), 1);
    std::vector<std::string> argv = c.spec.command;
    argv[0] = resolve(argv[0], options.bin_dir);
    std::vector<char*> cargv;
    for (auto& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    ::execvp(cargv[0], cargv.data());
    std::fprintf(stderr, "cannot start '%s': %s\n", cargv[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(fds[1]);
  ::fcntl(fds[0], F_SETFL, O_NONBLOCK);
  c.pid = pid;
  c.fd = fds[0];
  c.started = Clock::now();
  say("started " + c.spec.name + " (pid " + std::to_string(pid) + ")");
  return true;
}

void emitLine(Child& c, const std::string& line, bool echo) {
  c.log << line << '\n';
  c.log.flush();
  if (echo) std::fprintf(stdout, "[%s] %s\n", c.spec.name.c_str(), line.c_str());
}

void drain(Child& c, bool echo) {
  char buf[4096];
  while (c.fd >= 0) {
    const ssize_t n = ::read(c.fd, buf, sizeof buf);
    if (n > 0) {
      c.partial.append(buf, static_cast<std::size_t>(n));
      std::size_t nl;
      while ((nl = c.partial.find('\n')) != std::string::npos) {
        emitLine(c, c.partial.substr(0, nl), echo);
        c.partial.erase(0, nl + 1);
      }
    } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
      if (!c.partial.empty()) emitLine(c, c.partial, echo);
      c.partial.clear();
      ::close(c.fd);
      c.fd = -1;
    } else {
      break;
    }
  }
  std::fflush(stdout);
}

std::string describe(int status) {
  if (WIFEXITED(status)) return "exited with code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + ::strsignal(WTERMSIG(status));
  return "stopped";
}

bool wantsRestart(const Child& c, int status) {
  const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  switch (c.spec.restart) {
    case Restart::Never: return false;
    case Restart::OnFailure: return !clean;
    case Restart::Always: return true;
  }
  return false;
}

void stopAll(std::vector<Child>& children, const SupervisorOptions& options) {
  // Reverse start order: the recorder (started first) stops last and sees everything.
  for (auto it = children.rbegin(); it != children.rend(); ++it) {
    Child& c = *it;
    if (c.pid <= 0) continue;
    ::kill(c.pid, SIGINT);
    const auto deadline = Clock::now() + seconds(options.stop_timeout_s);
    int status = 0;
    while (::waitpid(c.pid, &status, WNOHANG) == 0) {
      drain(c, options.echo);
      if (Clock::now() > deadline) {
        say(fmt::format("{} did not stop within {:g} s: killing it", c.spec.name, options.stop_timeout_s));
        ::kill(c.pid, SIGKILL);
        ::waitpid(c.pid, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    drain(c, options.echo);
    say("stopped " + c.spec.name + " (" + describe(status) + ")");
    c.pid = -1;
  }
}

}  // namespace

int supervise(const LaunchSpec& spec, const SupervisorOptions& options) {
  fs::create_directories(options.run_dir);
  std::vector<Child> children;
  if (!spec.record_channels.empty()) {
    Child rec;
    rec.spec = {"recorder", {"lcm-logger", "-q", "-f", "-c", spec.record_channels, (fs::path(options.run_dir) / "record.lcmlog").string()},
                Restart::OnFailure};
    children.push_back(std::move(rec));
  }
  for (const auto& p : spec.processes) {
    Child c;
    c.spec = p;
    children.push_back(std::move(c));
  }
  runtime::installStopHandlers();
  for (auto& c : children) {
    if (c.spec.delay_s > 0) std::this_thread::sleep_for(seconds(c.spec.delay_s));
    c.log.open(fs::path(options.run_dir) / (c.spec.name + ".log"), std::ios::app);
    if (!start(c, spec, options)) {
      say("cannot start " + c.spec.name + ": " + std::strerror(errno));
      stopAll(children, options);
      return 1;
    }
    if (c.spec.name == "recorder") std::this_thread::sleep_for(std::chrono::milliseconds(300));  // subscribed before data flows
  }

  const auto run_start = Clock::now();
  std::optional<Clock::time_point> stop_at;
  if (options.duration_s > 0) stop_at = run_start + seconds(options.duration_s);
  while (!runtime::stopRequested() && !(stop_at && Clock::now() >= *stop_at)) {
    std::vector<pollfd> pfds;
    for (auto& c : children)
      if (c.fd >= 0) pfds.push_back({c.fd, POLLIN, 0});
    ::poll(pfds.data(), pfds.size(), 100);
    for (auto& c : children) drain(c, options.echo);

    int status = 0;
    pid_t pid;
    while ((pid = ::waitpid(-1, &status, WNOHANG)) > 0) {
      auto it = std::find_if(children.begin(), children.end(), [pid](const Child& c) { return c.pid == pid; });
      if (it == children.end()) continue;
      Child& c = *it;
      drain(c, options.echo);
      c.pid = -1;
      const double ran_s = std::chrono::duration<double>(Clock::now() - c.started).count();
      if (std::find(spec.stop_when_exit.begin(), spec.stop_when_exit.end(), c.spec.name) != spec.stop_when_exit.end()) {
        say(fmt::format("{} {}: ending the run in {:g} s", c.spec.name, describe(status), spec.grace_s));
        c.finished = true;
        const auto end = Clock::now() + seconds(spec.grace_s);
        if (!stop_at || end < *stop_at) stop_at = end;
      } else if (wantsRestart(c, status)) {
        if (ran_s > 30.0) c.backoff_s = 1.0;  // it had been healthy: start the back-off afresh
        say(fmt::format("{} {}: restarting in {:g} s", c.spec.name, describe(status), c.backoff_s));
        c.next_start = Clock::now() + seconds(c.backoff_s);
        c.backoff_s = std::min(30.0, c.backoff_s * 2.0);
      } else {
        say(c.spec.name + " " + describe(status) + ": not restarting");
        c.finished = true;
      }
    }
    for (auto& c : children)
      if (c.pid < 0 && !c.finished && Clock::now() >= c.next_start && c.fd < 0) start(c, spec, options);
  }
  say(runtime::stopRequested() ? "interrupted: stopping" : "run complete: stopping");
  stopAll(children, options);
  return 0;
}

}  // namespace adit::launch
