// infolerp_pareto SUBCOMMAND [options]: dispatches to the time-against-error harnesses.
#include <cstdio>
#include <cstring>
#include "pareto.hpp"

int main(int argc, char** argv) {
  using sub_fn = int (*)(int, char**);
  struct sub {
    const char* name;
    sub_fn fn;
  };
  const sub subs[] = {{"refine", &pareto_refine}, {"upsample", &pareto_upsample}, {"walk", &pareto_walk}, {"lod", &pareto_lod},
                      {"visibility", &pareto_visibility}, {"saliency", &pareto_saliency},
                      {"pipeline", &pareto_pipeline}, {"lod_dag", &pareto_lod_dag}};
  for (const sub& s : subs)
    if (argc >= 2 && std::strcmp(argv[1], s.name) == 0 && s.fn != nullptr) return s.fn(argc - 1, argv + 1);
  std::fprintf(stderr, "usage: infolerp_pareto refine|upsample|walk|lod|visibility|saliency|pipeline|lod_dag [options]\n");
  return 2;
}
