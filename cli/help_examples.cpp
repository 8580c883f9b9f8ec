// The "Examples:" footer of every command's --help, in one table so that a new
// command shows up here missing (addExamples throws; the CLI tests read every
// command's help). The lines run from the source tree's root, one after the
// other: the files the first ones write are the inputs of later ones.
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cli/help_format.hpp"

namespace sailshape::cli {
namespace {

struct CommandExamples {
  const char* path;  // the command's words after `sailshape`; "" for `sailshape` itself
  std::vector<const char*> lines;
};

const std::vector<CommandExamples>& examples() {
  static const std::vector<CommandExamples> table = {
      {"", {"sailshape demo", "sailshape analyze assets/sample-main-scene.ply --sections 5"}},
      {"analyze",
       {"sailshape analyze assets/sample-main-scene.ply --sections 5 --viewpoint -8,-9,5 --json main.json "
        "--mesh main-surface.ply",
        "sailshape analyze --describe-params"}},
      {"simulate",
       {"sailshape simulate --type main --out main.ply --truth main-truth.json",
        "sailshape simulate --type gennaker --scene --points 100000 --noise-mm 4 --out a2-scene.ply"}},
      {"design",
       {"sailshape design new --type main --out main-design.obj",
        "sailshape design show main-design.obj --sections 5"}},
      {"design new",
       {"sailshape design new --type main --out main-design.obj",
        "sailshape design new --type gennaker --luff 12.4 --leech 11 --foot 6.5 --camber-pct 18,24,16 "
        "--out a2-design.stl"}},
      {"design show",
       {"sailshape design show main-design.obj --sections 5",
        "sailshape design show a2-design.stl --unit m --axes boat --json a2-design.json"}},
      {"compare",
       {"sailshape compare --design main-design.obj --flying main.ply --no-segment --json compare.json",
        "sailshape compare --design main-design.obj --flying main.ply --no-segment --distances deviation.ply "
        "--whole-sail whole-sail.ply"}},
      {"fit",
       {"sailshape fit --design main-design.obj --flying main.ply --no-segment --out main-fitted.ply --json fit.json",
        "sailshape fit --design main-design.obj --flying assets/sample-main-scene.ply --out main-fitted.obj "
        "--iterations 12"}},
      {"demo", {"sailshape demo", "sailshape demo --dir demo-quick --steps 2 --scan-lines 300 --quiet"}},
      {"db", {"sailshape db init trials.db", "sailshape db query trials.db --sections --csv"}},
      {"db init", {"sailshape db init trials.db"}},
      {"db import",
       {"sailshape db import trials.db main.json --sail 'Main 1' --sail-type mainsail --test Sheet --trim-step 1 "
        "--awa 30",
        "sailshape db import trials.db main.ply --campaign 'Tunnel 2026' --campaign-kind wind_tunnel --sail 'Main 1' "
        "--set sheet=0.2"}},
      {"db design",
       {"sailshape db design add trials.db --sail 'Main 1' main-design.obj",
        "sailshape db design list trials.db --sail 'Main 1'"}},
      {"db design add",
       {"sailshape db design add trials.db --sail 'Main 1' main-design.obj",
        "sailshape db design add trials.db --sail A2 a2-design.stl --unit m --axes boat"}},
      {"db design list", {"sailshape db design list trials.db --sail 'Main 1'"}},
      {"db design show",
       {"sailshape db design show trials.db --sail 'Main 1'",
        "sailshape db design show trials.db --sail 'Main 1' --version 1 --json main-v1.json"}},
      {"db design export", {"sailshape db design export trials.db --sail 'Main 1' --version 1 main-v1.stl"}},
      {"crop",
       {"sailshape crop main.ply --design main-design.obj --out main-crop.ply",
        "sailshape crop main.ply --box -4,0.5,-1,1.5,0.5,11.5 --out main-box.ply"}},
      {"db list", {"sailshape db list trials.db", "sailshape db list trials.db --sail 'Main 1' --csv"}},
      {"db show", {"sailshape db show trials.db 1", "sailshape db show trials.db 2 --json --cloud scan2.ply"}},
      {"db query",
       {"sailshape db query trials.db --sections --sail 'Main 1'",
        "sailshape db query trials.db --test Sheet --evolution camber_pct --fraction 0.5 --json"}},
      {"db export",
       {"sailshape db export trials.db sections.csv --sections --csv",
        "sailshape db export demo-output/sailshape.db twist.json --test 'A2 tack ease' --evolution twist_deg --json"}},
      {"db check", {"sailshape db check trials.db"}},
      {"db backup", {"sailshape db backup trials.db trials-backup.db"}},
      {"db copy", {"sailshape db copy trials.db trials-copy.db", "sailshape db copy trials.db trials-copy.db --append"}},
      {"replay",
       {"sailshape replay demo-output/captures/step1-tunnel-main-lms511.sscap --json frames.json",
        "sailshape replay demo-output/captures/step1-tunnel-main-lms511.sscap --unit "
        "demo-output/tunnel-main-lms511.json --cloud step1-main.ply"}},
      {"report",
       {"sailshape report --db demo-output/sailshape.db --scan 1 --out scan1.pdf",
        "sailshape report --db demo-output/sailshape.db --test 'A2 tack ease' --sail 'Demo 36 A2' --audience crew "
        "--out a2-crew.pdf"}},
      {"register",
       {"sailshape register --reference demo-output/clouds/step1-main-roi.ply --moving "
        "demo-output/clouds/step2-main-roi.ply --method icp --out step2-to-step1.txt --json registration.json",
        "sailshape register --transform step2-to-step1.txt --moving demo-output/clouds/step2-main-roi.ply --apply "
        "step2-in-step1.ply"}},
      {"emulate",
       {"sailshape emulate --model lms511 --unit assets/unit-tunnel-leeward.json --port 2112 --serial-link "
        "/tmp/sailshape-turntable-leeward",
        "sailshape emulate --model lms111 --port 0 --duration 60"}},
      {"scan",
       {"sailshape scan --unit assets/unit-tunnel-leeward.json --out scan1",
        "sailshape scan --unit assets/unit-tunnel-leeward.json --unit assets/unit-tunnel-windward.json --trigger "
        "--out scan2"}},
      // The boxes (unit frame, metres) keep the tunnel's floor and ceiling as the leeward unit sees them.
      {"scanner",
       {"sailshape scanner calibrate --plane scan1/tunnel-leeward.samples.csv@-8,8,-2.5,11,-2.1,-1.7 --plane "
        "scan1/tunnel-leeward.samples.csv@-8,8,-2.5,11,1.7,2.1 --unit assets/unit-tunnel-leeward.json --write-unit "
        "leeward-calibrated.json"}},
      {"scanner calibrate",
       {"sailshape scanner calibrate --plane scan1/tunnel-leeward.samples.csv@-8,8,-2.5,11,-2.1,-1.7 --plane "
        "scan1/tunnel-leeward.samples.csv@-8,8,-2.5,11,1.7,2.1 --unit assets/unit-tunnel-leeward.json --write-unit "
        "leeward-calibrated.json",
        "sailshape scanner calibrate --plane scan1/tunnel-leeward.samples.csv@-8,8,-2.5,11,-2.1,-1.7 --plane "
        "scan1/tunnel-leeward.samples.csv@-8,8,-2.5,11,1.7,2.1 --p0 0.1 --theta0 10 --json calibration.json --span "
        // The floor and the ceiling 3.8 m apart (the tunnel's height) give the range scale.
        "scan1/tunnel-leeward.samples.csv@-8,8,-2.5,11,-2.1,-1.7:scan1/tunnel-leeward.samples.csv@-8,8,-2.5,11,1.7,2.1=3.8"}},
  };
  return table;
}

}  // namespace

void addExamples(CLI::App& app) {
  for (const CommandExamples& e : examples()) {
    CLI::App* cmd = &app;
    std::istringstream words(e.path);
    for (std::string word; words >> word;) cmd = cmd->get_subcommand(word);  // throws for an unknown name
    std::string footer = "Examples:";
    for (const char* line : e.lines) footer += std::string("\n  ") + line;
    cmd->footer(footer);
  }
}

}  // namespace sailshape::cli
