#!/usr/bin/env python3
# Tests of scripts/check_layers.py on small fake trees (ctest Style.LayerCheckerCatchesWrongWayIncludes):
# a correct tree passes; wrong-way includes of header-only modules, a study file reaching past core,
# a PRIVATE link taken as transitive, and an unused link are each reported, with file and line; a
# whole-archive INTERFACE wrapper passes its link on.
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                      "check_layers.py")

# A miniature of the real layout: one target per solver/ folder, three targets in driver/.
GOOD_TREE = {
    "solver/CMakeLists.txt": "add_subdirectory(core)\nadd_subdirectory(particles)\n",
    "solver/core/CMakeLists.txt": """
        configure_file(version.hpp.in ${CMAKE_CURRENT_BINARY_DIR}/generated/core/version.hpp @ONLY)
        add_library(boycott_core STATIC core.cpp)  # target_link_libraries(boycott_core boycott_io)
        target_include_directories(boycott_core PUBLIC ${PROJECT_SOURCE_DIR}/solver)
        target_link_libraries(boycott_core PUBLIC fmt::fmt PRIVATE PkgConfig::TOMLPP)
        """,
    "solver/core/core.cpp": '#include "core/core.hpp"\n#include <vector>\n',
    "solver/core/core.hpp": "#pragma once\n",
    "solver/core/version.hpp.in": "#pragma once\n",
    "solver/particles/CMakeLists.txt": """
        add_library(boycott_particles STATIC
                    particles.cpp)
        target_link_libraries(boycott_particles PUBLIC boycott_core)
        """,
    "solver/particles/particles.cpp": '#include "particles/contact_models.hpp"\n#include "core/core.hpp"\n',
    "solver/particles/contact_models.hpp": "#pragma once\n",
    "solver/fluid/CMakeLists.txt": "add_library(boycott_fluid STATIC fluid.cpp)\n"
                                   "target_link_libraries(boycott_fluid PUBLIC boycott_core)\n",
    "solver/fluid/fluid.cpp": '#include "fluid/vreman.hpp"\n#include "core/core.hpp"\n',
    "solver/fluid/vreman.hpp": "#pragma once\n",
    "solver/coupling/CMakeLists.txt": "add_library(boycott_coupling STATIC coupler.cpp)\n"
                                      "target_link_libraries(boycott_coupling PUBLIC boycott_core "
                                      "boycott_particles boycott_fluid)\n",
    "solver/coupling/coupler.cpp": '#include "coupling/kernels.hpp"\n#include "core/core.hpp"\n'
                                   '#include "particles/contact_models.hpp"\n#include "fluid/vreman.hpp"\n',
    "solver/coupling/kernels.hpp": '#pragma once\n#include "core/core.hpp"\n',
    "driver/CMakeLists.txt": """
        set(GEN ${CMAKE_CURRENT_BINARY_DIR}/generated/schema_files.cpp)
        add_library(boycott_study STATIC study.cpp ${GEN})
        target_link_libraries(boycott_study PUBLIC boycott_core PkgConfig::SQLITE3)
        add_library(boycott_driver STATIC case_commands.cpp)
        target_link_libraries(boycott_driver PUBLIC boycott_coupling)
        add_executable(boycott main.cpp)
        target_link_libraries(boycott PRIVATE boycott_driver boycott_study CLI11::CLI11)
        """,
    "driver/study.cpp": '#include "driver/study.hpp"\n#include "driver/schema_files.hpp"\n'
                        '#include "core/version.hpp"\n',
    "driver/study.hpp": '#pragma once\n#include "core/core.hpp"\n',
    "driver/schema_files.hpp": "#pragma once\n",
    "driver/case_commands.cpp": '#include "driver/case_commands.hpp"\n#include "coupling/kernels.hpp"\n',
    "driver/case_commands.hpp": '#pragma once\n#include "fluid/vreman.hpp"\n',
    "driver/main.cpp": '#include "driver/case_commands.hpp"\n#include "driver/study.hpp"\n'
                       '#include "driver/schema_files.hpp"\n#include "particles/contact_models.hpp"\n',
}


class CheckLayersTest(unittest.TestCase):
    def run_on(self, changes=None, appends=None):
        """Writes GOOD_TREE with `changes` (path -> new text) and `appends` (path -> extra text),
        runs the checker on it, returns (exit status, stdout lines, stderr)."""
        files = dict(GOOD_TREE)
        files.update(changes or {})
        for path, extra in (appends or {}).items():
            files[path] = files[path] + extra
        with tempfile.TemporaryDirectory() as root:
            for path, text in files.items():
                full = os.path.join(root, path)
                os.makedirs(os.path.dirname(full), exist_ok=True)
                with open(full, "w") as f:
                    f.write(textwrap.dedent(text))
            r = subprocess.run([sys.executable, SCRIPT, "--root", root], capture_output=True, text=True,
                               timeout=60)
        return r.returncode, r.stdout.splitlines(), r.stderr

    def assertViolations(self, result, expected):
        rc, lines, _ = result
        self.assertEqual(rc, 1, lines)
        self.assertEqual(lines[:-1], expected)
        self.assertEqual(lines[-1], f"check_layers: {len(expected)} violation(s)")

    def test_accepts_a_correct_tree(self):
        rc, lines, warnings = self.run_on()
        self.assertEqual(rc, 0, lines)
        self.assertEqual(len(lines), 1)
        self.assertTrue(lines[0].startswith("check_layers: OK, 7 targets, 14 files"), lines)
        self.assertEqual(warnings, "")  # core/version.hpp resolved as version.hpp.in, all files owned

    def test_catches_a_wrong_way_include_of_a_header_only_module(self):
        wrong = '#include "coupling/kernels.hpp"\n'
        self.assertViolations(self.run_on(appends={"solver/particles/particles.cpp": wrong}),
                              ["solver/particles/particles.cpp:3 includes coupling/kernels.hpp: "
                               "particles does not link coupling"])
        # also from a header, with angle brackets, between two siblings that never see each other
        wrong = "  #  include <fluid/vreman.hpp>\n"
        self.assertViolations(self.run_on(appends={"solver/particles/contact_models.hpp": wrong}),
                              ["solver/particles/contact_models.hpp:2 includes fluid/vreman.hpp: "
                               "particles does not link fluid"])

    def test_study_sees_core_only(self):
        self.assertViolations(
            self.run_on(appends={"driver/study.cpp": '#include "fluid/vreman.hpp"\n'
                                                     '#include "driver/case_commands.hpp"\n',
                                 "driver/study.hpp": '#include "core/core.hpp"\n'}),
            ["driver/study.cpp:4 includes fluid/vreman.hpp: study does not link fluid",
             # case_commands.hpp belongs to boycott_driver, the target of case_commands.cpp
             "driver/study.cpp:5 includes driver/case_commands.hpp: study does not link driver"])
        # a core header includes a driver one: solver/ never sees driver/
        self.assertViolations(
            self.run_on(appends={"solver/core/core.hpp": '#include "driver/schema_files.hpp"\n'}),
            ["solver/core/core.hpp:2 includes driver/schema_files.hpp: core does not link study"])

    def test_private_links_do_not_propagate(self):
        changes = {"solver/coupling/CMakeLists.txt":
                   "add_library(boycott_coupling STATIC coupler.cpp)\n"
                   "target_link_libraries(boycott_coupling PUBLIC boycott_core boycott_fluid "
                   "PRIVATE boycott_particles)\n"}
        self.assertViolations(self.run_on(changes),
                              ["driver/main.cpp:4 includes particles/contact_models.hpp: "
                               "boycott does not link particles"])

    def test_ignores_comments_and_if_0(self):
        extra = textwrap.dedent('''\
            // #include "coupling/kernels.hpp"
            /* #include "coupling/kernels.hpp"
            #include "fluid/vreman.hpp" */
            #if 0
            #include "coupling/kernels.hpp"
            #endif
            const char* s = "#include \\"coupling/kernels.hpp\\"";
            ''')
        rc, lines, _ = self.run_on(appends={"solver/particles/particles.cpp": extra})
        self.assertEqual(rc, 0, lines)

    def test_reports_an_unused_link(self):
        io_cmake = ("add_library(boycott_io STATIC state_io.cpp)\n"
                    "target_link_libraries(boycott_io PUBLIC boycott_core boycott_particles "
                    "boycott_coupling)\n")
        io_cpp = '#include "core/core.hpp"\n#include "particles/contact_models.hpp"\n'
        self.assertViolations(
            self.run_on({"solver/io/CMakeLists.txt": io_cmake, "solver/io/state_io.cpp": io_cpp}),
            ["solver/io/CMakeLists.txt:2 io links coupling but no file of io includes a header of coupling "
             "(or of a target only coupling brings in): unused link"])
        # fluid comes only through coupling, so including a fluid header uses the coupling link
        # (an indirect one, but not unused); a header of io's own counts as a file of io
        rc, lines, _ = self.run_on({"solver/io/CMakeLists.txt": io_cmake,
                                    "solver/io/state_io.cpp": io_cpp,
                                    "solver/io/state_io.hpp": '#include "fluid/vreman.hpp"\n'})
        self.assertEqual(rc, 0, lines)

    def test_a_whole_archive_wrapper_passes_its_link_on(self):
        # scenes: a static library linked whole through an INTERFACE wrapper of no files, as
        # solver/scenes/CMakeLists.txt does; the wrapper's link counts for what links it.
        scenes_cmake = ("add_library(boycott_scene_code STATIC scene.cpp)\n"
                        "target_link_libraries(boycott_scene_code PUBLIC boycott_coupling)\n"
                        "add_library(boycott_scenes INTERFACE)\n"
                        "target_link_libraries(boycott_scenes INTERFACE "
                        "\"$<LINK_LIBRARY:WHOLE_ARCHIVE,boycott_scene_code>\")\n")
        runs_cmake = ("add_library(boycott_runs STATIC run_case.cpp)\n"
                      "target_link_libraries(boycott_runs PUBLIC boycott_scenes)\n")
        changes = {"solver/scenes/CMakeLists.txt": scenes_cmake,
                   "solver/scenes/scene.cpp": '#include "scenes/scene.hpp"\n#include "coupling/kernels.hpp"\n',
                   "solver/scenes/scene.hpp": "#pragma once\n",
                   "solver/runs/CMakeLists.txt": runs_cmake,
                   "solver/runs/run_case.cpp": '#include "scenes/scene.hpp"\n#include "fluid/vreman.hpp"\n'}
        rc, lines, _ = self.run_on(changes)
        self.assertEqual(rc, 0, lines)
        # without the wrapper's link, runs does not see the scenes
        changes["solver/scenes/CMakeLists.txt"] = scenes_cmake.replace(
            "\"$<LINK_LIBRARY:WHOLE_ARCHIVE,boycott_scene_code>\"", "")
        self.assertViolations(self.run_on(changes),
                              ["solver/runs/CMakeLists.txt:2 runs links scenes but no file of runs includes "
                               "a header of scenes (or of a target only scenes brings in): unused link",
                               "solver/runs/run_case.cpp:1 includes scenes/scene.hpp: runs does not link scene_code",
                               "solver/runs/run_case.cpp:2 includes fluid/vreman.hpp: runs does not link fluid"])


if __name__ == "__main__":
    unittest.main()
