#include "support/in_child.hpp"

#include <cerrno>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <poll.h>
#include <cstdlib>
#include <sys/wait.h>
#include <unistd.h>

namespace infolerp::support {

namespace {

bool write_all(int fd, const std::vector<char>& bytes) {
  for (std::size_t at = 0; at < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + at, bytes.size() - at);
    if (n <= 0) return false;
    at += static_cast<std::size_t>(n);
  }
  return true;
}

// Everything the child writes to fd until it closes it; false when `limit` passes first.
bool read_all(int fd, std::chrono::milliseconds limit, std::vector<char>& bytes) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  char chunk[65536];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{fd, POLLIN, 0};
    const int ready = left.count() > 0 ? ::poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1 << 30))) : 0;
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) return false;
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return true;
    bytes.insert(bytes.end(), chunk, chunk + n);
  }
}

}  // namespace

child_result run_in_child(const std::function<void(byte_writer&)>& work, std::chrono::milliseconds limit) {
  int fds[2];
  const pid_t child = ::pipe(fds) == 0 ? ::fork() : -1;
  if (child < 0) {  // no child: run here
    byte_writer out;
    work(out);
    return {out.bytes(), true, {}};
  }
  if (child == 0) {
    ::close(fds[0]);
    for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(sig, SIG_DFL);
    byte_writer out;
    work(out);
    std::_Exit(write_all(fds[1], out.bytes()) ? 0 : 1);
  }
  ::close(fds[1]);
  child_result r;
  const bool finished = read_all(fds[0], limit, r.bytes);
  ::close(fds[0]);
  if (!finished) ::kill(child, SIGKILL);
  int how = 0;
  while (::waitpid(child, &how, 0) < 0)
    if (errno != EINTR) {  // reaped elsewhere (SIGCHLD ignored): the bytes tell whether it finished
      r.completed = finished && !r.bytes.empty();
      return r;
    }
  r.completed = finished && WIFEXITED(how) && WEXITSTATUS(how) == 0;
  if (!finished) r.death = "it did not finish in " + std::to_string(limit.count()) + " ms";
  else if (WIFSIGNALED(how)) r.death = ::strsignal(WTERMSIG(how));
  else if (!r.completed) r.death = "exit status " + std::to_string(WEXITSTATUS(how));
  return r;
}

}  // namespace infolerp::support
