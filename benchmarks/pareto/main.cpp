// infolerp_pareto SUBCOMMAND [options]: time-versus-error experiments, one per subcommand.
#include <cstdio>
#include <cstring>
#include "pareto.hpp"

int main(int argc, char** argv) {
  struct sub {
    const char* name;
    int (*run)(int, char**);
  };
  const sub subs[] = {{"refine", pareto_refine}, {"upsample", pareto_upsample}};
  for (const sub& s : subs)
    if (argc >= 2 && std::strcmp(argv[1], s.name) == 0 && s.run != nullptr) return s.run(argc - 1, argv + 1);
  std::fprintf(stderr, "usage: %s SUBCOMMAND --csv FILE\nsubcommands:", argv[0]);
  for (const sub& s : subs)
    if (s.run != nullptr) std::fprintf(stderr, " %s", s.name);
  std::fprintf(stderr, "\n");
  return 2;
}
