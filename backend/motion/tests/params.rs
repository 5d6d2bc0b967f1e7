//! MC_AxisParameter table and storage (spec §6.11.8; acceptance item §11a-32).

use motion::params::{self, PARAMETERS, ParamGroup, ParamType, ParamValue, ParameterInfo, Unit};
use motion::{AxisParameters, AxisStatus, ErrorId};
use proptest::prelude::*;

/// The spec table (§6.11.8): number, exact name, manual type.
const SPEC: &[(u16, &str, &str)] = &[
    (1, "CommandedPosition", "LREAL"),
    (2, "SWLimitPos", "LREAL"),
    (3, "SWLimitNeg", "LREAL"),
    (4, "EnableLimitPos", "BOOL"),
    (5, "EnableLimitNeg", "BOOL"),
    (6, "EnablePosLagMonitoring", "BOOL"),
    (7, "MaxPositionLag", "LREAL"),
    (8, "MaxVelocitySystem", "LREAL"),
    (9, "MaxVelocityAppl", "LREAL"),
    (10, "ActualVelocity", "LREAL"),
    (11, "CommandedVelocity", "LREAL"),
    (12, "MaxAccelerationSystem", "LREAL"),
    (13, "MaxAccelerationAppl", "LREAL"),
    (14, "MaxDecelerationSystem", "LREAL"),
    (15, "MaxDecelerationAppl", "LREAL"),
    (16, "MaxJerkSystem", "LREAL"),
    (17, "MaxJerkAppl", "LREAL"),
    (1000, "AxisId", "LREAL"),
    (1001, "AxisVeloManSlow", "LREAL"),
    (1002, "AxisVeloManFast", "LREAL"),
    (1003, "AxisVeloMax", "LREAL"),
    (1004, "AxisAcc", "LREAL"),
    (1005, "AxisDec", "LREAL"),
    (1006, "AxisJerk", "LREAL"),
    (1007, "MaxJerk", "LREAL"),
    (1008, "AxisMaxVelocity", "LREAL"),
    (1009, "AxisRapidTraverseVelocity", "LREAL"),
    (1010, "AxisManualVelocityFast", "LREAL"),
    (1011, "AxisManualVelocitySlow", "LREAL"),
    (1012, "AxisCalibrationVelocityForward", "LREAL"),
    (1013, "AxisCalibrationVelocityBackward", "LREAL"),
    (1014, "AxisJogIncrementForward", "LREAL"),
    (1015, "AxisJogIncrementBackward", "LREAL"),
    (1016, "AxisEnMinSoftPosLimit", "BOOL"),
    (1017, "AxisMinSoftPosLimit", "LREAL"),
    (1018, "AxisEnMaxSoftPosLimit", "BOOL"),
    (1019, "AxisMaxSoftPosLimit", "LREAL"),
    (1020, "AxisEnPositionLagMonitoring", "BOOL"),
    (1021, "AxisMaxPosLagValue", "LREAL"),
    (1022, "AxisMaxPosLagFilterTime", "LREAL"),
    (1023, "AxisEnPositionRangeMonitoring", "BOOL"),
    (1024, "AxisPositionRangeWindow", "LREAL"),
    (1025, "AxisEnTargetPositionMonitoring", "BOOL"),
    (1026, "AxisTargetPositionWindow", "LREAL"),
    (1027, "AxisTargetPositionMonitoringTime", "LREAL"),
    (1028, "AxisEnInTargetTimeout", "BOOL"),
    (1029, "AxisInTargetTimeout", "LREAL"),
    (1030, "AxisEnMotionMonitoring", "BOOL"),
    (1031, "AxisMotionMonitoringWindow", "LREAL"),
    (1032, "AxisMotionMonitoringTime", "LREAL"),
    (1033, "AxisDelayTimeVeloPosition", "LREAL"),
    (1034, "AxisEnLoopingDistance", "BOOL"),
    (1035, "AxisLoopingDistance", "LREAL"),
    (1036, "AxisBacklash", "LREAL"),
    (1037, "AxisEnDataPersistence", "BOOL"),
    (1038, "AxisRefVeloOnRefOutput", "LREAL"),
    (1039, "AxisOverrideType", "LREAL"),
    (1040, "AxisEncoderScalingFactor", "LREAL"),
    (1041, "AxisEncoderOffset", "LREAL"),
    (1042, "AxisEncoderDirectionInverse", "BOOL"),
    (1043, "AxisEncoderMask", "DWORD"),
    (1044, "AxisEncoderModuloValue", "LREAL"),
    (1045, "AxisModuloToleranceWindow", "LREAL"),
    (1046, "AxisEnablePosCorrection", "BOOL"),
    (1047, "AxisPosCorrectionFilterTime", "LREAL"),
    (1048, "AxisUnitInterpretation", "LREAL"),
    (1049, "AxisMotorDirectionInverse", "BOOL"),
    (1050, "AxisCycleTime", "LREAL"),
    (1051, "AxisFastStopSignalType", "DWORD"),
    (1052, "AxisFastAcc", "LREAL"),
    (1053, "AxisFastDec", "LREAL"),
    (1054, "AxisFastJerk", "LREAL"),
    (1055, "AxisEncoderScalingNumerator", "LREAL"),
    (1056, "AxisEncoderScalingDenominator", "LREAL"),
    (1057, "AxisMaximumAcceleration", "LREAL"),
    (1058, "AxisMaximumDeceleration", "LREAL"),
    (1059, "AxisVeloJumpFactor", "LREAL"),
    (1060, "AxisToleranceBallAuxAxis", "LREAL"),
    (1061, "AxisMaxPositionDeviationAuxAxis", "LREAL"),
    (1062, "AxisErrorPropagationMode", "DWORD"),
    (1063, "AxisErrorPropagationDelay", "LREAL"),
    (1064, "AxisCoupleSlaveToActualValues", "BOOL"),
    (1065, "AxisAllowMotionCmdToSlaveAxis", "BOOL"),
    (1066, "AxisAllowMotionCmdToExtSetAxis", "BOOL"),
    (1067, "AxisEncoderSubMask", "DWORD"),
    (1068, "AxisEncoderReferenceSystem", "DWORD"),
    (1069, "AxisEncoderPositionFilterPT1", "LREAL"),
    (1070, "AxisEncoderVelocityFilterPT1", "LREAL"),
    (1071, "AxisEncoderAccelerationFilterPT1", "LREAL"),
    (1072, "AxisEncoderMode", "DWORD"),
    (1073, "AxisEncoderHomingInvDirCamSearch", "BOOL"),
    (1074, "AxisEncoderHomingInvDirSyncSearch", "BOOL"),
    (1075, "AxisEncoderHomingCalibValue", "LREAL"),
    (1076, "AxisEncoderReferenceMode", "DWORD"),
    (1077, "AxisRefVeloOutputRatio", "LREAL"),
    (1078, "AxisDrivePositionOutputScaling", "LREAL"),
    (1079, "AxisDriveVelocityOutputScaling", "LREAL"),
    (1080, "AxisDriveVelocityOutputDelay", "LREAL"),
    (1081, "AxisDriveMinOutputLimitation", "LREAL"),
    (1082, "AxisDriveMaxOutputLimitation", "LREAL"),
    (1083, "AxisTorqueInputScaling", "LREAL"),
    (1084, "AxisTorqueInputFilterPT1", "LREAL"),
    (1085, "AxisTorqueDerivationInputFilterPT1", "LREAL"),
    (1086, "AxisTorqueOutputScaling", "LREAL"),
    (1087, "AxisTorqueOutputDelay", "LREAL"),
    (1088, "AxisAccelerationOutputScaling", "LREAL"),
    (1089, "AxisAccelerationOutputDelay", "LREAL"),
    (1090, "AxisDrivePosOutputSmoothFilterType", "DWORD"),
    (1091, "AxisDrivePosOutputSmoothFilterTime", "LREAL"),
    (1092, "AxisDrivePosOutputSmoothFilterOrder", "DWORD"),
    (1093, "AxisDriveMode", "DWORD"),
    (1094, "AxisDriftCompensationOffset", "LREAL"),
    (1095, "AxisPositionControlKv", "LREAL"),
    (1096, "AxisCtrlVelocityPreCtrlWeight", "LREAL"),
    (1097, "AxisControllerMode", "DWORD"),
    (1098, "AxisCtrlAutoOffset", "BOOL"),
    (1099, "AxisCtrlAutoOffsetTimer", "LREAL"),
    (1100, "AxisCtrlAutoOffsetLimit", "LREAL"),
    (1101, "AxisSlaveCouplingControlKcp", "LREAL"),
    (1102, "AxisCtrlOutputLimit", "LREAL"),
    (2000, "AxisTargetPosition", "LREAL"),
    (2001, "AxisRemainingTimeToGo", "LREAL"),
    (2002, "AxisRemainingDistanceToGo", "LREAL"),
    (2003, "AxisMcSetPositionOffset", "LREAL"),
    (3000, "AxisGearRatio", "LREAL"),
    (4000, "NcSafCycleTime", "LREAL"),
    (4001, "NcSvbCycleTime", "LREAL"),
];

fn writable() -> impl Iterator<Item = &'static ParameterInfo> {
    PARAMETERS.iter().filter(|p| !p.read_only)
}

/// A valid value for `info` that differs from its current value in `p`.
fn other_valid(p: &AxisParameters, info: &ParameterInfo) -> ParamValue {
    let current = p.get(info.number).expect("storage entry");
    if let ParamValue::Bool(b) = current {
        return ParamValue::Bool(!b);
    }
    let cur = current.as_number().unwrap();
    let mut candidates = vec![cur + 1.0, cur * 0.5, cur + 0.25, 1.0, 2.0, 0.5, 0.0, -1.0];
    if info.min.is_finite() {
        candidates.push(info.min + 1.0);
        candidates.push(info.min);
    }
    if info.max.is_finite() {
        candidates.push(info.max);
        candidates.push(info.max - 1.0);
    }
    let x = candidates
        .into_iter()
        .find(|&x| x != cur && info.in_range(x))
        .unwrap_or_else(|| panic!("no valid value for {}", info.name));
    ParamValue::Number(x)
}

#[test]
fn s11a_32_every_spec_entry_is_present_once_in_order() {
    let ours: Vec<(u16, &str)> = PARAMETERS.iter().map(|p| (p.number, p.name)).collect();
    let spec: Vec<(u16, &str)> = SPEC.iter().map(|&(n, name, _)| (n, name)).collect();
    assert_eq!(ours, spec);
    for w in PARAMETERS.windows(2) {
        assert!(
            w[0].number < w[1].number,
            "{} before {}",
            w[0].number,
            w[1].number
        );
    }
    for &(n, name, ty) in SPEC {
        let info = params::by_number(n).unwrap();
        let expected = match ty {
            "BOOL" => ParamType::Bool,
            "LREAL" => ParamType::Real,
            "DWORD" => ParamType::DWord,
            other => panic!("unexpected type {other}"),
        };
        assert_eq!(info.ty, expected, "{name}");
    }
}

#[test]
fn names_are_unique_ignoring_case() {
    for (i, a) in PARAMETERS.iter().enumerate() {
        for b in &PARAMETERS[i + 1..] {
            assert!(
                !a.name.eq_ignore_ascii_case(b.name),
                "{} / {}",
                a.name,
                b.name
            );
        }
        assert!(
            !a.help.is_empty() && !a.ads_index_offset.is_empty(),
            "{}",
            a.name
        );
    }
}

#[test]
fn storage_status_and_read_only_classification() {
    let status: Vec<u16> = PARAMETERS
        .iter()
        .filter(|p| p.is_status())
        .map(|p| p.number)
        .collect();
    assert_eq!(status, [1, 10, 11, 2000, 2001, 2002, 2003]);
    let read_only: Vec<u16> = PARAMETERS
        .iter()
        .filter(|p| p.read_only)
        .map(|p| p.number)
        .collect();
    assert_eq!(
        read_only,
        [
            1, 10, 11, 1000, 1050, 2000, 2001, 2002, 2003, 3000, 4000, 4001
        ]
    );
    for p in PARAMETERS {
        assert!(
            p.storage == 0 || params::by_number(p.storage).is_some_and(|c| c.storage == c.number),
            "{}",
            p.name
        );
        assert_eq!(p.is_status(), p.group == ParamGroup::Status, "{}", p.name);
    }
}

/// The alias groups of the spec (same ADS index offset ⇒ same storage).
const ALIAS_GROUPS: &[&[u16]] = &[
    &[2, 1019],
    &[3, 1017],
    &[4, 1018],
    &[5, 1016],
    &[6, 1020],
    &[7, 1021],
    &[8, 9, 1003, 1008],
    &[12, 13, 1004],
    &[14, 15, 1005],
    &[16, 17, 1006, 1007],
    &[1001, 1011],
    &[1002, 1010],
];

#[test]
fn s11a_32_alias_groups_are_exactly_the_spec_ones() {
    let mut grouped: Vec<u16> = ALIAS_GROUPS
        .iter()
        .flat_map(|g| g.iter().copied())
        .collect();
    grouped.sort_unstable();
    let mut ours: Vec<u16> = PARAMETERS
        .iter()
        .filter(|p| p.is_alias() || p.aliases().next().is_some())
        .map(|p| p.number)
        .collect();
    ours.sort_unstable();
    assert_eq!(ours, grouped);
    for group in ALIAS_GROUPS {
        let storage = params::by_number(group[0]).unwrap().storage;
        for &n in *group {
            assert_eq!(params::by_number(n).unwrap().storage, storage, "#{n}");
        }
        // Same ADS index offset inside a group.
        let offsets: Vec<&str> = group
            .iter()
            .map(|&n| params::by_number(n).unwrap().ads_index_offset)
            .collect();
        assert!(offsets.windows(2).all(|w| w[0] == w[1]), "{offsets:?}");
    }
}

#[test]
fn s11a_32_aliases_share_storage_both_ways() {
    for group in ALIAS_GROUPS {
        for &writer in *group {
            let mut p = AxisParameters::default();
            let info = params::by_number(writer).unwrap();
            let v = other_valid(&p, info);
            p.set(writer, v)
                .unwrap_or_else(|e| panic!("#{writer} {v}: {e}"));
            for &reader in *group {
                assert_eq!(p.get(reader), Ok(v), "write #{writer}, read #{reader}");
                assert_eq!(
                    p.read(reader, &AxisStatus::default()),
                    Ok(v),
                    "write #{writer}, read #{reader}"
                );
            }
        }
    }
    // The example of §11a-32 / §4.2.10: SWLimitPos = 2000 reads back as AxisMaxSoftPosLimit.
    let mut p = AxisParameters::default();
    p.set(2, ParamValue::Number(2000.0)).unwrap();
    assert_eq!(p.get(1019), Ok(ParamValue::Number(2000.0)));
    assert_eq!(p.axis_max_soft_pos_limit, 2000.0);
    p.set(1019, ParamValue::Number(-5.0)).unwrap();
    assert_eq!(p.get(2), Ok(ParamValue::Number(-5.0)));
}

#[test]
fn s11a_32_write_then_read_every_writable_entry() {
    let mut count = 0;
    for info in writable() {
        let mut p = AxisParameters::default();
        let v = other_valid(&p, info);
        assert_eq!(p.set(info.number, v), Ok(()), "{} = {v}", info.name);
        assert_eq!(p.get(info.number), Ok(v), "{}", info.name);
        assert_eq!(
            p.read(info.number, &AxisStatus::default()),
            Ok(v),
            "{}",
            info.name
        );
        count += 1;
    }
    assert_eq!(count, 115);
}

#[test]
fn read_only_entries_refuse_writes_and_change_nothing() {
    for info in PARAMETERS.iter().filter(|p| p.read_only) {
        let mut p = AxisParameters::default();
        let before = p.clone();
        for v in [
            ParamValue::Number(0.002),
            ParamValue::Number(1.0),
            ParamValue::Bool(true),
        ] {
            assert_eq!(
                p.set(info.number, v),
                Err(ErrorId::PARAMETER_READ_ONLY),
                "{}",
                info.name
            );
        }
        assert_eq!(p, before, "{}", info.name);
    }
}

#[test]
fn types_are_enforced_with_0x4b05() {
    assert_eq!(ErrorId::COMMAND_NOT_PERMITTED.0, 0x4B05);
    for info in writable() {
        let mut p = AxisParameters::default();
        let before = p.clone();
        let wrong = match info.ty {
            ParamType::Bool => ParamValue::Number(1.0),
            ParamType::Real | ParamType::DWord => ParamValue::Bool(true),
        };
        assert_eq!(
            p.set(info.number, wrong),
            Err(ErrorId::COMMAND_NOT_PERMITTED),
            "{}",
            info.name
        );
        if info.ty == ParamType::DWord {
            assert_eq!(
                p.set(info.number, ParamValue::Number(1.5)),
                Err(ErrorId::COMMAND_NOT_PERMITTED),
                "{}",
                info.name
            );
        }
        assert_eq!(p, before, "{}", info.name);
    }
    // Bool into an LREAL, the example of the brief.
    let mut p = AxisParameters::default();
    assert_eq!(
        p.set(1003, ParamValue::Bool(true)),
        Err(ErrorId::COMMAND_NOT_PERMITTED)
    );
    assert_eq!(
        p.set(2, ParamValue::Bool(false)),
        Err(ErrorId::COMMAND_NOT_PERMITTED)
    );
}

#[test]
fn ranges_are_enforced() {
    for info in writable().filter(|p| p.ty != ParamType::Bool) {
        let mut p = AxisParameters::default();
        let before = p.clone();
        let mut bad = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY];
        if info.min.is_finite() {
            bad.push(if info.min_exclusive {
                info.min
            } else {
                info.min - 1.0
            });
        }
        if info.max.is_finite() {
            bad.push(info.max + 1.0);
        }
        if info.is_integral() && info.ty == ParamType::Real {
            bad.push(info.min.max(0.0) + 1.5);
        }
        for x in bad {
            assert_eq!(
                p.set(info.number, ParamValue::Number(x)),
                Err(ErrorId::PARAMETER_OUT_OF_RANGE),
                "{} = {x}",
                info.name
            );
        }
        assert_eq!(p, before, "{}", info.name);
    }
    let mut p = AxisParameters::default();
    for (n, x) in [
        (1003, 0.0),
        (1004, -1.0),
        (1006, 0.0),
        (1026, -0.001),
        (1029, -1.0),
        (1044, 0.0),
        (1076, 8.0),
        (1039, 0.0),
        (1096, 101.0),
    ] {
        assert_eq!(
            p.set(n, ParamValue::Number(x)),
            Err(ErrorId::PARAMETER_OUT_OF_RANGE),
            "#{n} = {x}"
        );
    }
    for (n, x) in [
        (1076, 7.0),
        (1076, 0.0),
        (1026, 0.0),
        (1017, -1e9),
        (1043, 4294967295.0),
    ] {
        assert_eq!(p.set(n, ParamValue::Number(x)), Ok(()), "#{n} = {x}");
    }
    assert_eq!(
        p.set(1043, ParamValue::Number(4294967296.0)),
        Err(ErrorId::PARAMETER_OUT_OF_RANGE)
    );
    assert_eq!(
        p.set(1043, ParamValue::Number(-1.0)),
        Err(ErrorId::PARAMETER_OUT_OF_RANGE)
    );
}

#[test]
fn unknown_numbers_and_names() {
    let mut p = AxisParameters::default();
    for n in [0, 18, 999, 1103, 1999, 2004, 3001, 4002, u16::MAX] {
        assert!(params::by_number(n).is_none());
        assert_eq!(p.get(n), Err(ErrorId::PARAMETER_UNKNOWN));
        assert_eq!(
            p.read(n, &AxisStatus::default()),
            Err(ErrorId::PARAMETER_UNKNOWN)
        );
        assert_eq!(
            p.set(n, ParamValue::Number(1.0)),
            Err(ErrorId::PARAMETER_UNKNOWN)
        );
        p.set_raw(n, 1.0);
    }
    assert_eq!(p, AxisParameters::default());
    assert_eq!(params::lookup("1003").map(|i| i.name), Some("AxisVeloMax"));
    assert_eq!(params::lookup("axisvelomax").map(|i| i.number), Some(1003));
    assert_eq!(params::lookup("SWLIMITPOS").map(|i| i.number), Some(2));
    assert_eq!(params::lookup(" 2 ").map(|i| i.name), Some("SWLimitPos"));
    assert_eq!(
        params::by_name("AxisEnMinSoftPosLimit").map(|i| i.number),
        Some(1016)
    );
    assert!(params::lookup("NoSuchParameter").is_none());
    assert!(params::lookup("1103").is_none());
    assert!(params::lookup("").is_none());
}

#[test]
fn status_entries_are_read_from_the_axis_status() {
    let status = AxisStatus {
        set_position: 11.0,
        actual_velocity: 22.0,
        set_velocity: 33.0,
        target_position: 44.0,
        remaining_time: 55.0,
        remaining_distance: 66.0,
        set_position_offset: 77.0,
        gear_ratio: 0.25,
        ..AxisStatus::default()
    };
    let p = AxisParameters::default();
    for (n, v) in [
        (1, 11.0),
        (10, 22.0),
        (11, 33.0),
        (2000, 44.0),
        (2001, 55.0),
        (2002, 66.0),
        (2003, 77.0),
        (3000, 0.25),
    ] {
        assert_eq!(p.read(n, &status), Ok(ParamValue::Number(v)), "#{n}");
    }
    for n in [1, 10, 11, 2000, 2001, 2002, 2003] {
        assert_eq!(
            p.get(n),
            Err(ErrorId::PARAMETER_UNKNOWN),
            "#{n} has no storage"
        );
    }
    // 3000 has a kernel-written slot.
    let mut p = p;
    p.set_raw(3000, -2.0);
    assert_eq!(p.get(3000), Ok(ParamValue::Number(-2.0)));
    assert_eq!(p.axis_gear_ratio, -2.0);
    assert_eq!(
        p.set(3000, ParamValue::Number(1.0)),
        Err(ErrorId::PARAMETER_READ_ONLY)
    );
    assert_eq!(p.read(1003, &status), Ok(ParamValue::Number(500.0)));
}

#[test]
fn set_raw_writes_read_only_slots_and_converts_types() {
    let mut p = AxisParameters::default();
    p.set_raw(1050, 0.004);
    p.set_raw(4000, 0.002);
    p.set_raw(4001, 0.01);
    p.set_raw(1000, 7.0);
    p.set_raw(5, 1.0); // alias of AxisEnMinSoftPosLimit
    p.set_raw(1076, 3.0);
    p.set_raw(9, 800.0);
    assert_eq!(
        (
            p.axis_cycle_time,
            p.nc_saf_cycle_time,
            p.nc_svb_cycle_time,
            p.axis_id
        ),
        (0.004, 0.002, 0.01, 7.0)
    );
    assert!(p.axis_en_min_soft_pos_limit);
    assert_eq!(p.axis_encoder_reference_mode, 3);
    assert_eq!(p.axis_velo_max, 800.0);
    p.set_raw(5, 0.0);
    assert!(!p.axis_en_min_soft_pos_limit);
    p.set_raw(1, 5.0); // status: ignored
    assert_eq!(p.validate(), Ok(()));
}

#[test]
fn defaults_are_valid_and_keep_the_seed_values() {
    let p = AxisParameters::default();
    assert_eq!(p.validate(), Ok(()));
    assert_eq!(
        (p.axis_velo_max, p.axis_acc, p.axis_dec, p.axis_jerk),
        (500.0, 2500.0, 2500.0, 25000.0)
    );
    assert_eq!((p.axis_velo_man_slow, p.axis_velo_man_fast), (10.0, 50.0));
    assert_eq!(
        (p.axis_encoder_modulo_value, p.axis_modulo_tolerance_window),
        (360.0, 1.0)
    );
    assert_eq!(p.axis_cycle_time, 0.001);
    assert!(p.axis_en_target_position_monitoring && p.axis_en_position_lag_monitoring);
    for (info, v) in p.entries() {
        assert_eq!(info.check(v), Ok(()), "default of {} = {v}", info.name);
    }
}

#[test]
fn validate_cross_checks() {
    type Case = (&'static str, fn(&mut AxisParameters), u16);
    let cases: &[Case] = &[
        (
            "soft limits crossed",
            |p| {
                p.axis_en_min_soft_pos_limit = true;
                p.axis_en_max_soft_pos_limit = true;
                p.axis_min_soft_pos_limit = 10.0;
                p.axis_max_soft_pos_limit = 10.0;
            },
            1017,
        ),
        ("acc above maximum", |p| p.axis_acc = 20000.0, 1004),
        (
            "dec above maximum",
            |p| p.axis_maximum_deceleration = 100.0,
            1005,
        ),
        ("slow jog above max", |p| p.axis_velo_man_slow = 600.0, 1001),
        ("fast jog above max", |p| p.axis_velo_max = 40.0, 1002),
        (
            "rapid traverse above max",
            |p| p.axis_rapid_traverse_velocity = 501.0,
            1009,
        ),
        (
            "calibration forward above max",
            |p| p.axis_calibration_velocity_forward = 501.0,
            1012,
        ),
        (
            "calibration backward above max",
            |p| p.axis_calibration_velocity_backward = 501.0,
            1013,
        ),
        (
            "modulo window too wide",
            |p| p.axis_modulo_tolerance_window = 180.0,
            1045,
        ),
        (
            "modulo value zero",
            |p| p.axis_encoder_modulo_value = 0.0,
            1044,
        ),
        (
            "drive output limits crossed",
            |p| p.axis_drive_min_output_limitation = 1.0,
            1081,
        ),
        (
            "scaling inconsistent",
            |p| p.axis_encoder_scaling_factor = 2.0,
            1040,
        ),
        ("NaN velocity", |p| p.axis_velo_max = f64::NAN, 1003),
        (
            "reference mode 8",
            |p| p.axis_encoder_reference_mode = 8,
            1076,
        ),
        ("cycle time 0", |p| p.axis_cycle_time = 0.0, 1050),
    ];
    for (what, break_it, number) in cases {
        let mut p = AxisParameters::default();
        break_it(&mut p);
        let issue = p.validate().expect_err(what);
        assert_eq!(issue.number, *number, "{what}: {}", issue.message);
        assert_eq!(issue.error, ErrorId::PARAMETER_OUT_OF_RANGE, "{what}");
        assert!(!issue.message.is_empty());
    }
    // Limits only checked when both are enabled.
    let p = AxisParameters {
        axis_en_max_soft_pos_limit: true,
        axis_min_soft_pos_limit: 10.0,
        ..Default::default()
    };
    assert_eq!(p.validate(), Ok(()));
}

#[test]
fn set_consistent_refuses_inconsistent_writes() {
    let mut p = AxisParameters::default();
    let before = p.clone();
    let issue = p
        .set_consistent(1003, ParamValue::Number(20.0))
        .unwrap_err();
    assert_eq!(issue.number, 1002); // AxisVeloManFast 50 > 20
    assert_eq!(p, before);
    assert_eq!(
        p.set_consistent(1003, ParamValue::Bool(true))
            .unwrap_err()
            .error,
        ErrorId::COMMAND_NOT_PERMITTED
    );
    assert_eq!(p.set_consistent(1011, ParamValue::Number(5.0)), Ok(()));
    assert_eq!(p.set_consistent(1010, ParamValue::Number(8.0)), Ok(()));
    assert_eq!(p.set_consistent(1012, ParamValue::Number(8.0)), Ok(()));
    assert_eq!(p.set_consistent(1009, ParamValue::Number(8.0)), Ok(()));
    assert_eq!(p.set_consistent(8, ParamValue::Number(20.0)), Ok(()));
    assert_eq!(p.axis_velo_max, 20.0);
}

#[test]
fn encoder_scaling_factor_follows_numerator_and_denominator() {
    let mut p = AxisParameters::default();
    p.set(1055, ParamValue::Number(1.0)).unwrap();
    p.set(1056, ParamValue::Number(4.0)).unwrap();
    assert_eq!(p.get(1040), Ok(ParamValue::Number(0.25)));
    p.set(1040, ParamValue::Number(0.001)).unwrap();
    assert_eq!(
        (
            p.axis_encoder_scaling_numerator,
            p.axis_encoder_scaling_denominator
        ),
        (0.001, 1.0)
    );
    assert_eq!(p.validate(), Ok(()));
    // A derived factor out of range refuses the write.
    p.set(1055, ParamValue::Number(1e300)).unwrap();
    let before = p.clone();
    assert_eq!(
        p.set(1056, ParamValue::Number(1e-10)),
        Err(ErrorId::PARAMETER_OUT_OF_RANGE)
    );
    assert_eq!(p, before);
}

#[test]
fn entries_cover_every_storage_slot_once() {
    let p = AxisParameters::default();
    let e: Vec<_> = p.entries().collect();
    let canonical = PARAMETERS
        .iter()
        .filter(|i| !i.is_status() && !i.is_alias())
        .count();
    assert_eq!(e.len(), canonical);
    assert_eq!(e.len(), 127 - 7 - 18);
    for (info, v) in e {
        assert!(!info.is_alias() && !info.is_status());
        assert_eq!(p.get(info.number), Ok(v));
    }
}

#[test]
fn units_groups_and_serialization() {
    assert_eq!(Unit::Acceleration.text("mm"), "mm/s²");
    assert_eq!(Unit::Velocity.text("°"), "°/s");
    assert_eq!(Unit::Jerk.text("mm"), "mm/s³");
    assert_eq!(Unit::Position.text("mm"), "mm");
    assert_eq!(Unit::Seconds.text("mm"), "s");
    assert_eq!(Unit::Code.text("mm"), "");
    assert_eq!(params::by_number(1006).unwrap().unit.generic(), "u/s³");
    assert_eq!(ParamGroup::ALL.len(), 11);
    for p in PARAMETERS {
        assert!(ParamGroup::ALL.contains(&p.group));
    }

    let info = serde_json::to_value(params::by_number(1003).unwrap()).unwrap();
    assert_eq!(info["name"], "AxisVeloMax");
    assert_eq!(info["type"], "lreal");
    assert_eq!(info["unit"], "velocity");
    assert_eq!(info["group"], "dynamics");
    assert_eq!(info["min"], 0.0);
    assert_eq!(info["min_exclusive"], true);
    assert!(info["max"].is_null());
    assert_eq!(
        serde_json::to_value(params::by_number(1043).unwrap()).unwrap()["type"],
        "dword"
    );
    assert_eq!(
        serde_json::to_value(params::by_number(1016).unwrap()).unwrap()["type"],
        "bool"
    );
    assert_eq!(
        serde_json::to_value(ParamGroup::Controller).unwrap(),
        "controller"
    );

    assert_eq!(
        serde_json::from_str::<ParamValue>("true").unwrap(),
        ParamValue::Bool(true)
    );
    assert_eq!(
        serde_json::from_str::<ParamValue>("5").unwrap(),
        ParamValue::Number(5.0)
    );
    assert_eq!(
        serde_json::from_str::<ParamValue>("-2.5").unwrap(),
        ParamValue::Number(-2.5)
    );
    assert!(serde_json::from_str::<ParamValue>("\"5\"").is_err());
    assert_eq!(
        serde_json::to_string(&ParamValue::Bool(false)).unwrap(),
        "false"
    );
    assert_eq!(
        serde_json::to_string(&ParamValue::Number(800.0)).unwrap(),
        "800.0"
    );
}

fn any_value() -> impl Strategy<Value = ParamValue> {
    prop_oneof![
        any::<bool>().prop_map(ParamValue::Bool),
        (-10i64..5000).prop_map(|i| ParamValue::Number(i as f64)),
        (-1e4f64..1e5).prop_map(ParamValue::Number),
        (0.0f64..2.0).prop_map(ParamValue::Number),
        prop_oneof![
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(f64::NEG_INFINITY),
            Just(-0.0),
            Just(4294967295.0),
            Just(4294967296.0),
            Just(1e308),
            Just(1e-308)
        ]
        .prop_map(ParamValue::Number),
    ]
}

fn any_number() -> impl Strategy<Value = u16> {
    prop_oneof![
        8 => (0..PARAMETERS.len()).prop_map(|i| PARAMETERS[i].number),
        1 => any::<u16>(),
    ]
}

/// Every stored value lies in its entry's range and the scaling triple is coupled.
fn fields_in_range(p: &AxisParameters) -> Result<(), String> {
    for (info, v) in p.entries() {
        info.check(v)
            .map_err(|e| format!("{} = {v}: {e}", info.name))?;
    }
    if p.axis_encoder_scaling_factor
        != p.axis_encoder_scaling_numerator / p.axis_encoder_scaling_denominator
    {
        return Err("scaling factor decoupled".into());
    }
    Ok(())
}

proptest! {
    #[test]
    fn random_sets_fail_cleanly_or_take_effect(writes in prop::collection::vec((any_number(), any_value()), 1..60)) {
        let mut p = AxisParameters::default();
        for (n, v) in writes {
            let before = p.clone();
            match p.set(n, v) {
                Ok(()) => {
                    prop_assert_eq!(p.get(n), Ok(v));
                    let info = params::by_number(n).unwrap();
                    prop_assert!(!info.read_only);
                }
                Err(e) => {
                    prop_assert_eq!(&p, &before, "failed set #{} = {} changed something", n, v);
                    prop_assert!([ErrorId::PARAMETER_UNKNOWN, ErrorId::PARAMETER_READ_ONLY, ErrorId::COMMAND_NOT_PERMITTED, ErrorId::PARAMETER_OUT_OF_RANGE].contains(&e));
                }
            }
            prop_assert_eq!(fields_in_range(&p), Ok(()));
        }
    }

    #[test]
    fn random_consistent_sets_keep_the_set_valid(writes in prop::collection::vec((any_number(), any_value()), 1..60)) {
        let mut p = AxisParameters::default();
        for (n, v) in writes {
            let before = p.clone();
            match p.set_consistent(n, v) {
                Ok(()) => prop_assert_eq!(p.get(n), Ok(v)),
                Err(_) => prop_assert_eq!(&p, &before),
            }
            prop_assert_eq!(p.validate(), Ok(()));
        }
    }

    #[test]
    fn set_raw_never_panics(n in any::<u16>(), x in any::<f64>()) {
        let mut p = AxisParameters::default();
        p.set_raw(n, x);
        let _ = p.validate();
        let _ = p.entries().count();
    }
}

/// The kernel's checked write (`AxisParameters::write`, a BOOL as 0/1) agrees with the
/// server's `set` for every entry of the table, and a refused write changes nothing.
#[test]
fn the_kernels_write_checks_like_set_for_every_entry() {
    for info in PARAMETERS {
        for x in [
            0.0,
            1.0,
            -1.0,
            0.5,
            2.0,
            1e12,
            -1e12,
            f64::NAN,
            f64::INFINITY,
        ] {
            let value = match info.ty {
                ParamType::Bool if x == 0.0 || x == 1.0 => ParamValue::Bool(x == 1.0),
                ParamType::Bool => continue,
                _ => ParamValue::Number(x),
            };
            let mut by_set = AxisParameters::default();
            let expected = by_set
                .set(info.number, value)
                .and_then(|()| by_set.validate().map_err(|i| i.error));
            let mut by_write = AxisParameters::default();
            let got = by_write.write(info.number, x);
            assert_eq!(got, expected, "#{} {} = {x}", info.number, info.name);
            if got.is_ok() {
                assert_eq!(by_write, by_set, "#{} = {x}", info.number);
            } else {
                assert_eq!(
                    by_write,
                    AxisParameters::default(),
                    "#{} = {x}",
                    info.number
                );
            }
        }
    }
    // A BOOL other than 0/1 is out of range.
    let mut p = AxisParameters::default();
    assert_eq!(p.write(1018, 0.5), Err(ErrorId::PARAMETER_OUT_OF_RANGE));
    assert_eq!(
        p.write(1018, f64::NAN),
        Err(ErrorId::PARAMETER_OUT_OF_RANGE)
    );
}
