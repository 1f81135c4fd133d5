# ctest driver for infolerp_demo (examples/CMakeLists.txt):
#   MODE=errors  bad options and bad files: each gives exit code 1 or 2 (not a signal) and exactly
#                one line on stderr that says what is wrong
#   MODE=run     a small run (65x65, AO 4, soft 2, --threads 2, then --passes auto at 33x33):
#                exit 0 and every output file written (each PNG a non-empty file with the PNG
#                signature); then two --mesh files (33x33), each reported with what it lacks
# Arguments: -DDEMO=<infolerp_demo> -DWORK_DIR=<scratch dir> -DMODE=errors|run
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(expect_error expected_rc pattern)
  execute_process(COMMAND ${DEMO} ${ARGN} --size 17 17 --ao 1 --soft 1 --out ${WORK_DIR}/out
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(REGEX MATCHALL "\n" lines "${err}")
  list(LENGTH lines nlines)
  if(NOT rc STREQUAL "${expected_rc}" OR NOT nlines EQUAL 1 OR NOT err MATCHES "^infolerp_demo: .*${pattern}")
    message(FATAL_ERROR "infolerp_demo ${ARGN}\n  expected exit ${expected_rc} and one stderr line matching "
                        "'${pattern}'\n  got exit '${rc}', ${nlines} line(s):\n${err}")
  endif()
  message(STATUS "ok (${rc}): ${ARGN} -> ${err}")
endfunction()

function(expect_files)
  foreach(f IN LISTS ARGN)
    if(NOT EXISTS ${f})
      message(FATAL_ERROR "missing output ${f}")
    endif()
    file(SIZE ${f} size)
    if(size EQUAL 0)
      message(FATAL_ERROR "empty output ${f}")
    endif()
    if(f MATCHES "\\.png$")
      file(READ ${f} signature LIMIT 8 HEX)
      if(NOT signature STREQUAL "89504e470d0a1a0a" OR size LESS 100)
        message(FATAL_ERROR "not a PNG file: ${f} (${size} bytes, starts with ${signature})")
      endif()
    endif()
  endforeach()
endfunction()

if(MODE STREQUAL "errors")
  expect_error(2 "unknown option '--bogus'" --bogus)
  expect_error(2 "unknown option 'extra'" extra)
  expect_error(2 "--size needs two integers" --size 0 10)
  expect_error(2 "--size needs two integers" --size 10)
  expect_error(2 "--passes needs K" --passes 0)
  expect_error(2 "--passes needs K" --passes 17)
  expect_error(2 "--passes needs K" --passes fast)
  expect_error(2 "--threads needs an integer" --threads 0)
  expect_error(2 "--tessellate needs a share of the image in \\[0, 1\\]" --tessellate 2)
  expect_error(2 "--tessellate needs a share of the image in \\[0, 1\\]" --tessellate much)
  expect_error(2 "--threshold: unknown channel 'colour'" --threshold colour=0.5)
  expect_error(2 "--threshold: visibility value '1.5' is not a number in \\[0, 1\\]" --threshold visibility=1.5)
  expect_error(2 "--threshold: stretch value '-0.1'" --threshold stretch=-0.1)
  expect_error(2 "--threshold: orientation value 'nan'" --threshold orientation=nan)
  expect_error(2 "--threshold needs CHANNEL=VALUE" --threshold visibility)
  expect_error(2 "--mesh needs a file name" --mesh)
  expect_error(2 "--group needs a name" --group)
  expect_error(2 "--up needs y or z" --up x)

  # Files: missing, not a mesh, truncated, counts the file cannot hold, an index out of range, a
  # NaN coordinate.
  expect_error(1 "cannot open mesh '${WORK_DIR}/missing.off'" --mesh ${WORK_DIR}/missing.off)
  expect_error(1 "cannot load mesh '${WORK_DIR}/missing.obj'" --mesh ${WORK_DIR}/missing.obj)
  file(WRITE ${WORK_DIR}/garbage.off "this is not a mesh\n")
  expect_error(1 "not an OFF file" --mesh ${WORK_DIR}/garbage.off)
  file(WRITE ${WORK_DIR}/truncated.off "OFF\n4 2 0\n0 0 0\n1 0 0\n# a comment long enough for the counts\n")
  expect_error(1 "line 5: truncated vertex list" --mesh ${WORK_DIR}/truncated.off)
  file(WRITE ${WORK_DIR}/huge.off "OFF\n1000000000000 1 0\n0 0 0\n")
  expect_error(1 "line 2: the header's counts \\(1000000000000 vertices, 1 faces\\) need more than the file's 28 bytes"
               --mesh ${WORK_DIR}/huge.off)
  file(WRITE ${WORK_DIR}/index.off "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 2 1 9\n")
  expect_error(1 "triangle 1 corner 2: vertex index 9 out of range \\(vertex count 4\\)" --mesh ${WORK_DIR}/index.off)
  file(WRITE ${WORK_DIR}/nan.off "OFF\n4 2 0\n0 0 0\n1 0 0\nnan 1 0\n1 1 0\n3 0 1 2\n3 2 1 3\n")
  expect_error(1 "vertex 2: non-finite position" --mesh ${WORK_DIR}/nan.off)
  file(WRITE ${WORK_DIR}/broken.obj "v 0 0 0\nv 1 0 0\nf 1 2 7\n")
  expect_error(1 "mesh '${WORK_DIR}/broken.obj'" --mesh ${WORK_DIR}/broken.obj)
  # A material whose diffuse texture is missing.
  file(WRITE ${WORK_DIR}/tri.obj "mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n")
  file(WRITE ${WORK_DIR}/tri.mtl "newmtl m\nKd 1 1 1\nmap_Kd missing.png\n")
  expect_error(1 "cannot read texture '${WORK_DIR}/missing.png'" --mesh ${WORK_DIR}/tri.obj)

  # An output directory that cannot be created (a regular file is in the way).
  file(WRITE ${WORK_DIR}/file "x")
  execute_process(COMMAND ${DEMO} --size 17 17 --out ${WORK_DIR}/file/out RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc STREQUAL "1" OR NOT err MATCHES "^infolerp_demo: cannot create output directory")
    message(FATAL_ERROR "unwritable --out: exit '${rc}': ${err}")
  endif()

  execute_process(COMMAND ${DEMO} --help RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "--passes K\\|auto")
    message(FATAL_ERROR "--help: exit '${rc}': ${out}")
  endif()
elseif(MODE STREQUAL "run")
  execute_process(COMMAND ${DEMO} --size 65 65 --ao 4 --soft 2 --threads 2 --passes 3 --threshold visibility=0.48
                          --out ${WORK_DIR}/out RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "small run: exit '${rc}'\n${out}\n${err}")
  endif()
  set(files reference.png saliency.png ibuffer.png rie.png error.png path.png lod.png lod_orbit.png summary.csv lod.csv tradeoff.png)
  list(TRANSFORM files PREPEND ${WORK_DIR}/out/)
  expect_files(${files})
  file(STRINGS ${WORK_DIR}/out/summary.csv rows)
  list(GET rows 0 header)
  list(LENGTH rows nrows)
  if(NOT header MATCHES "^method,seconds,speedup,psnr_db,ssim" OR nrows LESS 6 OR NOT "${rows}" MATCHES "reference,.*ibuffer-3,"
     OR "${rows}" MATCHES "(^|;)lod-")
    message(FATAL_ERROR "summary.csv:\n${rows}")
  endif()
  foreach(stage IN ITEMS "load" "BVH" "reference" "clustering: visibility channel" "saliency" "LOD salient clustering"
                         "LOD metric infolerp 5%" "I-Buffer row ibuffer-3")
    if(NOT out MATCHES "\ntime: ${stage}[^\n]* [0-9.]+ s\n")
      message(FATAL_ERROR "the demo did not print the time of stage '${stage}':\n${out}")
    endif()
  endforeach()
  if(NOT out MATCHES "where the time went")
    message(FATAL_ERROR "no closing list of stage times:\n${out}")
  endif()
  # The LOD figures: their own table and lod.csv, the full mesh first, then each method at 35% and 5%.
  file(STRINGS ${WORK_DIR}/out/lod.csv rows)
  set(number "[0-9.e+-]+")
  if(NOT "${rows}" MATCHES "^method,fraction,triangles,seconds,weighted_distance,hausdorff,psnr_db,ssim;full,1.0000,[1-9][0-9]*,"
     OR NOT "${rows}" MATCHES ";infolerp,0.0500,[1-9][0-9]*,${number},${number},${number},${number},${number}(;|$)"
     OR NOT "${rows}" MATCHES ";infolerp,0.3500,[1-9][0-9]*,")
    message(FATAL_ERROR "lod.csv:\n${rows}")
  endif()
  if(NOT out MATCHES "\nLOD method +fraction +triangles +time \\(s\\) +weighted d. +Hausdorff +PSNR \\(dB\\) +SSIM\n"
     OR NOT out MATCHES "\ninfolerp +5% +[0-9]+ ")
    message(FATAL_ERROR "the demo printed no LOD table:\n${out}")
  endif()
  # lod.png: 3 x 3 panels of 65 pixels; lod_orbit.png: 6 cameras x 2 rows (PNG header: width, height).
  foreach(png_size IN ITEMS "lod.png:000000c3000000c3" "lod_orbit.png:0000018600000082")
    string(REPLACE ":" ";" png_size "${png_size}")
    list(GET png_size 0 f)
    list(GET png_size 1 expected)
    file(READ ${WORK_DIR}/out/${f} ihdr OFFSET 16 LIMIT 8 HEX)
    if(NOT ihdr STREQUAL expected)
      message(FATAL_ERROR "${f}: width and height ${ihdr}, expected ${expected}")
    endif()
  endforeach()
  if(NOT out MATCHES "\n  camera 5: [1-9][0-9]* triangles, [0-9]+% facing it \\(full mesh: [0-9]+%\\)\n")
    message(FATAL_ERROR "lod_orbit: no line for the sixth camera:\n${out}")
  endif()
  foreach(f IN ITEMS "reference.png" "lod_orbit.png" "summary.csv" "lod.csv" "tradeoff.png")
    if(NOT out MATCHES "wrote [^\n]*${f}")
      message(FATAL_ERROR "the demo did not say where ${f} went:\n${out}")
    endif()
  endforeach()

  execute_process(COMMAND ${DEMO} --size 33 33 --ao 2 --soft 1 --passes auto --out ${WORK_DIR}/auto
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "ibuffer-auto")
    message(FATAL_ERROR "--passes auto: exit '${rc}'\n${out}\n${err}")
  endif()
  expect_files(${WORK_DIR}/auto/ibuffer.png ${WORK_DIR}/auto/summary.csv)

  # --mesh is repeatable; meshes without a texture or without texcoords say what is skipped.
  file(WRITE ${WORK_DIR}/quad.obj "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
  file(WRITE ${WORK_DIR}/quad.off "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
  execute_process(COMMAND ${DEMO} --size 33 33 --ao 2 --soft 1 --mesh ${WORK_DIR}/quad.obj --mesh ${WORK_DIR}/quad.off
                          --out ${WORK_DIR}/meshes RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "scene: 6 objects" OR NOT out MATCHES "quad.obj[^\n]*no diffuse texture"
     OR NOT out MATCHES "quad.off[^\n]*no texcoords: stretch channel skipped")
    message(FATAL_ERROR "two --mesh: exit '${rc}'\n${out}\n${err}")
  endif()
  # The same two files as one Z-up group.
  execute_process(COMMAND ${DEMO} --size 33 33 --ao 2 --soft 1 --up z --group pair --mesh ${WORK_DIR}/quad.obj
                          --mesh ${WORK_DIR}/quad.off --out ${WORK_DIR}/group RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "scene: 6 objects")
    message(FATAL_ERROR "--group: exit '${rc}'\n${out}\n${err}")
  endif()
endif()
