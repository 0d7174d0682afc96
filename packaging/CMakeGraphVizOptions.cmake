# What `cmake --graphviz` draws for docs/images/layers.svg (packaging/layers-graph.sh): the
# project's libraries and how they link, not third-party libraries, programs, tests or generated
# resource targets.
set(GRAPHVIZ_GRAPH_NAME "LiverSim's libraries")
set(GRAPHVIZ_EXTERNAL_LIBS FALSE)
set(GRAPHVIZ_EXECUTABLES FALSE)
set(GRAPHVIZ_GENERATE_PER_TARGET FALSE)
set(GRAPHVIZ_GENERATE_DEPENDERS FALSE)
set(GRAPHVIZ_IGNORE_TARGETS "liversim_core;liversim_forces_without_.*;liversim_fake_hd;.*_tests$;liversim_fuzz.*;liversim_session_writer_child;liversim_training_centre_load;liversim_ui_resources.*;liversim_translations.*;liversim_icons.*")
