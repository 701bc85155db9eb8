// Child processes of `dhpd bench` (see child_process.hpp).
#include "tools/bench/child_process.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>

namespace dhpd::bench {

int run_child(const std::vector<std::string>& argv, const std::filesystem::path& log,
              long& peak_rss_bytes, const std::vector<std::pair<std::string, std::string>>& env) {
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, 1), dup2(fd, 2);
    for (const auto& [name, value] : env) setenv(name.c_str(), value.c_str(), 1);
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) < 0) return -1;
  rusage children{};
  getrusage(RUSAGE_CHILDREN, &children);  // mpirun's ranks are grandchildren
  peak_rss_bytes = std::max(usage.ru_maxrss, children.ru_maxrss) * 1024L;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace dhpd::bench
