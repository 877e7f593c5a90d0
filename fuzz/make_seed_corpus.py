#!/usr/bin/env python3
"""Writes the seed corpus fuzz/corpus/<target>/ (small synthetic inputs, valid and near-valid).

Every file here is made up: no CUReT data and nothing from ../shared. Run once after changing a
seed (`python3 fuzz/make_seed_corpus.py`); the files are committed.
"""

import math
import pathlib

CORPUS = pathlib.Path(__file__).resolve().parent / "corpus"
SEP = "\x1e"  # file separator of the curet_files target (fuzz/curet_files.cpp)


def write(target, name, text):
    path = CORPUS / target / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(text.encode("utf-8") if isinstance(text, str) else text)


# model --csv: theta_i,theta_s,phi_s (+ sigma_um, T_um, sigma_over_T)
write("model_csv", "valid_sigma_T.csv",
      "theta_i,theta_s,phi_s,sigma_um,T_um\n30,30,180,0.1,0.3\n45,0,0,2,5\n0,10,90,0.5,1\n")
write("model_csv", "valid_sigma_over_T.csv",
      "# very rough rows\ntheta_i,theta_s,phi_s,sigma_over_T\n\n0,0,180,0.5\n30,30,180,0.9\n")
write("model_csv", "bom_crlf_comments.csv",
      "\ufefftheta_i , theta_s,phi_s,label\r\n# a comment\r\n 10 ,20, -45,first\r\n89.9,0,360,x\r\n")
write("model_csv", "empty_optional_cells.csv",
      "theta_i,theta_s,phi_s,sigma_um,T_um,sigma_over_T\n30,30,180,,,0.4\n30,30,180,0.2,0.4,\n")
write("model_csv", "missing_column.csv", "theta_i,theta_s\n30,30\n")
write("model_csv", "bad_numbers.csv",
      "theta_i,theta_s,phi_s\n30,30,nan\n1.5x,0,0\n1e999,0,0\n0x1A,0,0\n")
write("model_csv", "angle_out_of_range.csv", "theta_i,theta_s,phi_s\n95,0,0\n-1,0,0\n")
write("model_csv", "wrong_field_count.csv", "theta_i,theta_s,phi_s\n30,30\n30,30,0,1\n")
write("model_csv", "duplicate_header.csv", "theta_i,theta_i,theta_s,phi_s\n1,2,3,4\n")
write("model_csv", "header_only.csv", "theta_i,theta_s,phi_s\n")

# estimate fit --measurements: theta_i,phi_i,theta_s,phi_s,brightness (+ weight)
write("fit_csv", "valid.csv",
      "theta_i,phi_i,theta_s,phi_s,brightness\n"
      "30,180,0,0,0.92\n45,180,0,0,0.81\n60,180,10,90,0.55\n20,0,20,180,1.1\n")
write("fit_csv", "valid_weights.csv",
      "theta_i,phi_i,theta_s,phi_s,brightness,weight\n"
      "10,0,10,180,1.2,1\n40,0,30,90,0.7,0.5\n70,0,0,0,0.2,2\n")
write("fit_csv", "crlf_bom.csv",
      "\ufefftheta_i,phi_i,theta_s,phi_s,brightness\r\n30,0,0,0,1\r\n\r\n45,0,0,0,0.9\r\n")
write("fit_csv", "bad_rows.csv",
      "theta_i,phi_i,theta_s,phi_s,brightness,weight\n90,0,0,0,1,1\n30,0,0,0,-1,1\n"
      "30,0,0,0,1,inf\n30,0,0,0,1,\n")
write("fit_csv", "missing_brightness.csv", "theta_i,phi_i,theta_s,phi_s\n30,0,0,0\n")

# curet --table: theta_i,phi_i,theta_s,phi_s,value (+ weight, channel, measurement)
write("brdf_table", "valid.csv",
      "theta_i,phi_i,theta_s,phi_s,value\n45,0,0,0,0.058\n67.5,0,0,0,0.041\n30,0,30,180,0.07\n")
write("brdf_table", "channels.csv",
      "# two channels\ntheta_i,phi_i,theta_s,phi_s,value,weight,channel,measurement\n"
      "45,0,0,0,0.05,1,red,1\n45,0,0,0,0.06,1,green,1\n67.5,0,0,0,0.03,0.5,red,2\n"
      "67.5,0,0,0,0.04,0.5,green,2\n")
write("brdf_table", "duplicate_measurement.csv",
      "theta_i,phi_i,theta_s,phi_s,value,measurement\n45,0,0,0,0.05,3\n30,0,0,0,0.06,3\n")
write("brdf_table", "near_valid.csv",
      "\ufefftheta_i,phi_i,theta_s,phi_s,value,weight\r\n45,0,0,0,-0.001,0\r\n90,0,0,0,1,1\r\n"
      "45,0,0,0,1,-1\r\n")
write("brdf_table", "measurement_not_integer.csv",
      "theta_i,phi_i,theta_s,phi_s,value,measurement\n45,0,0,0,0.05,1.5\n")


# CUReT: table.txt (205 rows: measurement theta_v phi_v theta_i phi_i, radians) and the
# per-sample files (sample number + 205 values), joined by SEP.
def angle_table(rows=205, bad_row=None):
    lines = []
    for j in range(1, rows + 1):
        theta_v = (j % 7) * 0.2
        phi_v = (j % 11) * 0.5 - 2.5
        theta_i = (j % 5) * 0.3
        phi_i = (j % 13) * 0.45
        line = f"{j} {theta_v:.6f} {phi_v:.6f} {theta_i:.6f} {phi_i:.6f}"
        if j == bad_row:
            line = f"{j} {theta_v:.6f} {phi_v:.6f} 1.6 {phi_i:.6f}"
        lines.append(line)
    return "\n".join(lines) + "\n"


def sample_line(sample, scale, fractions=False):
    values = []
    for j in range(1, 206):
        if fractions:
            values.append(f"{(j % 10) / 10:.1f}")
        else:
            values.append(f"{scale * (0.5 + 0.4 * math.sin(j)):.5f}")
    return f"{sample} " + " ".join(values) + "\n"


table = angle_table()
brdf = sample_line(3, 0.1) + sample_line(17, 0.02)
over = sample_line(3, 0, True) + sample_line(17, 0, True)
write("curet_files", "valid.txt", table + SEP + brdf)
write("curet_files", "valid_aover.txt", table + SEP + brdf + SEP + over)
write("curet_files", "valid_rover.txt", "\ufeff" + table.replace("\n", "\r\n") + SEP + brdf + SEP + SEP
      + over)
write("curet_files", "table_204_rows.txt", angle_table(204) + SEP + brdf)
write("curet_files", "table_bad_angle.txt", angle_table(bad_row=100) + SEP + brdf)
write("curet_files", "duplicate_sample.txt", table + SEP + sample_line(3, 0.1) + sample_line(3, 0.2))
write("curet_files", "short_sample_line.txt", table + SEP + "5 0.1 0.2 0.3\n")
write("curet_files", "overflow_missing_sample.txt",
      table + SEP + brdf + SEP + sample_line(3, 0, True))

# paper tables (layout of reference/paper-tables.json; synthetic numbers, not the paper's)
PAPER = """{
  "source": "synthetic seed",
  "table1_slightly_rough": {
    "conditions": {"specular_theta_deg": 20, "theta1_deg": 30, "theta2_deg": 50,
                   "lambda_um": 0.6, "F": "VH"},
    "rows": [{"surface": "A", "R_spec": 0.01, "sigma_um": 0.1, "E1_over_E2": 1.05,
              "T_um": 0.2, "sigma_over_T": 0.5}]
  },
  "table2_very_rough": {
    "conditions": {"theta1_deg": 30, "theta2_deg": 50, "F": "VH"},
    "rows": [{"surface": "B", "E1_over_E2": 1.1, "sigma_over_T_G": 0.7, "theta_K_deg": 40,
              "xi_K_percent": 30.5, "sigma_over_T_E": 1.6}]
  },
  "table3_curet_parameters": {
    "conditions": {"theta1_deg": 40, "theta2_deg": 60},
    "rows": [{"name": "C", "sample": 7, "E1_over_E2": 1.5, "sigma_over_T_G": 0.5,
              "sigma_over_T_E": 1.2}]
  }
}
"""
# capture_file: the capture file of `roughscope measure` (docs/measure.md).
CAPTURE = """{
  "format": "roughscope-measure", "wavelength_um": 0.555, "response": "srgb",
  "black_level_dn": [0, 0, 0], "roi": {"rect": [8, 8, 48, 48]}, "correlation": "gaussian",
  "regime": "slightly_rough", "sigma_um": 0.1, "highlight": {"core_radius_px": 3},
  "statistics": {"tile_size_px": 8},
  "captures": [
    {"image": "a.png", "theta_i_deg": 30, "exposure_s": 0.02},
    {"image": "b.png", "light": [0.7, 0, 0.7], "view": [0, 0, 1], "exposure_s": 0.01},
    {"image": "s.png", "theta_i_deg": 14, "theta_s_deg": 14, "role": "specular"},
    {"bracket": [{"image": "c1.png", "exposure_s": 1}, {"image": "c2.png", "exposure_s": 4}],
     "theta_i_deg": 45}
  ]
}
"""
write("capture_file", "valid.json", CAPTURE)
write("capture_file", "gamma_bracket.json", CAPTURE.replace('"response": "srgb"', '"response": {"bracket": [{"image": "k1.png", "exposure_s": 1}, {"image": "k2.png", "exposure_s": 2}]}'))
write("capture_file", "polygon.json", CAPTURE.replace('{"rect": [8, 8, 48, 48]}', '{"polygon": [[1, 1], [40, 2], [20, 30]]}'))
write("capture_file", "circle_gamma.json", CAPTURE.replace('{"rect": [8, 8, 48, 48]}', '{"circle": [30, 30, 10]}').replace('"response": "srgb"', '"response": {"gamma": 2.2}'))
write("capture_file", "unknown_key.json", CAPTURE.replace('"correlation"', '"colour": 1, "correlation"'))
write("capture_file", "angle_out_of_range.json", CAPTURE.replace('"theta_i_deg": 30', '"theta_i_deg": 95'))
write("capture_file", "truncated.json", CAPTURE[:150])
write("capture_file", "exposures_equal.json", CAPTURE.replace('"correlation"', '"exposures_equal": true, "correlation"').replace('"exposure_s": 0.01', '"exposure_s": 0.02'))
# Curved objects and maps (docs/measure.md "Curved objects and maps").
write("capture_file", "cylinder.json", """{
  "object": {"shape": "cylinder", "axis": {"point_px": [40, 30], "direction": [0, 1], "radius_px": 20},
             "half": "both", "bin_width_deg": 3, "sigma_over_T": 0.7, "departure_bins": 2},
  "captures": [{"image": "c.tiff", "light": [0, 0, 1]}]
}
""")
write("capture_file", "cylinder_edges.json", """{
  "object": {"shape": "cylinder", "edges": [[[10, 0], [10, 50]], [[50, 0], [50, 50]]]},
  "roi": {"rect": [0, 0, 60, 60]}, "captures": [{"image": "c.tiff", "theta_i_deg": 0}]
}
""")
write("capture_file", "sphere.json", """{
  "object": {"shape": "sphere"}, "captures": [{"image": "s.tiff", "light": [-0.5, 0, 0.866]}]
}
""")
write("capture_file", "maps.json", """{
  "object": {"shape": "normal_map", "file": "n.png"},
  "maps": {"window_px": 4, "max_shift_px": 0.5, "allow_misregistration": false,
           "both_correlations": true, "ratio_layer": false,
           "regions": [{"name": "a", "rect": [0, 0, 8, 8]}, {"name": "b", "circle": [9, 9, 3]}]},
  "captures": [{"image": "a.png", "light": [0.5, 0, 0.866]}, {"image": "b.png", "light": [0.7, 0, 0.7]}]
}
""")

write("paper_json", "valid.json", PAPER)
write("paper_json", "sample_not_integer.json", PAPER.replace('"sample": 7', '"sample": 7.5'))
write("paper_json", "ratio_is_string.json", PAPER.replace('"E1_over_E2": 1.1', '"E1_over_E2": "1.1"'))
write("paper_json", "no_solution.json", PAPER.replace('"E1_over_E2": 1.5', '"E1_over_E2": 0.5'))
write("paper_json", "missing_table.json",
      PAPER.split('"table3_curet_parameters"')[0].rstrip().rstrip(",") + "\n}\n")
write("paper_json", "rows_not_list.json", PAPER.replace('"rows": [{"surface": "B"', '"rows": {"x": [{"surface": "B"').replace('"sigma_over_T_E": 1.6}]', '"sigma_over_T_E": 1.6}]}'))
write("paper_json", "not_object.json", "[1, 2, 3]\n")
write("paper_json", "truncated.json", PAPER[:200])
