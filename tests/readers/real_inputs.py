"""Every real input of ../shared/real_data and ../shared/maps with its expected format."""

REAL_TRACES = [
    ("av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede", "av2-sensor"),
    ("av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76", "av2-sensor"),
    ("av2/forecasting/0a1e6f0a-1817-4a98-b02e-db8c9327d151", "av2-forecasting"),
    *[
        (f"nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{s}.pkl", "scenarionet")
        for s in ("0061", "0103", "0553", "0655", "0757", "0796", "0916", "1077", "1094", "1100")
    ],
    ("waymo_womd/sd_waymo_v1.2_eb4b91b10ca94ff2.pkl", "scenarionet"),
    ("waymo_womd/motion_data_one_scenario.tfrecord", "waymo-tfrecord"),
    ("waymo_womd/womd_scenario_input.tfrecord", "waymo-tfrecord"),
    *[
        (f"commonroad_ngsim/USA_{s}_T-1.xml", "commonroad")
        for s in ("US101-3_3", "US101-4_1", "Lanker-1_1", "Peach-4_8")
    ],
]
"""(path under real_data, format) of every real recording."""

REAL_MAPS = [
    (
        "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede/map/"
        "log_map_archive_7fab2350-7eaf-3b7e-a39d-6937a4c1bede____PIT_city_47896.json",
        "av2-map",
    ),
]
"""(path under real_data, format) of map-only files."""
