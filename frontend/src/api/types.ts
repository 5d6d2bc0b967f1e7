// Names for the generated OpenAPI types (schema.d.ts is generated: npm run gen:api).
import type { components } from './schema';

type S = components['schemas'];
export type AxisResource = S['AxisResource'];
export type AxisConfig = S['AxisConfigDto'];
export type AxisStatus = S['AxisStatus'];
/** The status as the server sends it (REST and websocket): the kernel's plus the master's name. */
export type AxisLiveStatus = S['LiveStatus'];
export type PeakResetResource = S['PeakResetResource'];
export type AxisState = S['AxisState'];
export type CommandResource = S['CommandResource'];
export type CommandState = S['CommandState'];
export type FbOutputs = S['FbOutputs'];
export type ParameterResource = S['ParameterResource'];
export type ParamGroup = S['ParamGroup'];
export type ParamValue = S['ParamValue'];
export type SystemResource = S['SystemResource'];
export type Problem = S['Problem'];
export type FieldError = S['FieldError'];
export type HomingMode = S['HomingMode'];
export type JogMode = S['JogMode'];
export type JogDirection = S['JogDirection'];
export type PowerBody = S['PowerBody'];
export type MoveBody = S['MoveBody'];
export type MoveVelocityBody = S['MoveVelocityBody'];
export type HomeBody = S['HomeBody'];
export type Direction = S['Direction'];
export type DriveConfig = S['DriveConfig'];
/** The simulated drive's configuration (`kind: "simulated"`, the default). */
export type SimDriveConfig = Extract<DriveConfig, { kind: 'simulated' }>;
/** A CiA-402 servo drive on the EtherCAT bus (`kind: "cia402"`). */
export type Cia402DriveConfig = Extract<DriveConfig, { kind: 'cia402' }>;
export type Cia402Mode = S['Cia402Mode'];
/** Who runs a CiA-402 axis's motion profile: motiond (`host`) or the drive (`drive`, Drive Motion Control). */
export type ProfileSide = S['ProfileSide'];
/** `GET /bus`: the drive bus (simulated, emulated or real EtherCAT) and its SubDevices. */
export type BusResource = S['BusResource'];
export type SubDeviceResource = S['SubDeviceResource'];
export type AlState = S['AlState'];
/** An object read from (or written to and read back from) a SubDevice by SDO. */
export type SdoValue = S['SdoValue'];
export type SdoWrite = S['SdoWrite'];
export type PlantModel = S['PlantModel'];

/** A `command_event` notification of the `commands` websocket topic. */
export interface CommandEvent {
  cycle: number;
  command: number;
  /** Empty for a group's command (see `group`). */
  axis: string;
  /** The group a group's command addresses. */
  group?: string;
  name: string;
  state: CommandState;
  final: boolean;
  outputs: FbOutputs;
}

/**
 * A `subscription_ended` notification: the server ended an axis topic's subscription because
 * the axis it followed (by id) is gone — deleted, or replaced by an import (`PUT /config`
 * gives new ids). Nothing more comes for the topic until it is subscribed again.
 */
export interface SubscriptionEnded {
  topic: string;
  reason: 'axis_removed';
}
export type CamTableResource = S['CamTableResource'];
export type CamTableBody = S['CamTableBody'];
export type MotionFunctionPoint = S['MotionFunctionPoint'];
export type MotionFunctionType = S['MotionFunctionType'];
export type MotionPointType = S['MotionPointType'];
export type CamCharacteristics = S['Characteristics'];
export type CamValuesResource = S['CamValuesResource'];
/** `POST /cam-analysis`: an unsaved table's values, characteristics and discontinuities. */
export type CamAnalysisResource = S['CamAnalysisResource'];
export type CamDiscontinuity = S['Discontinuity'];
/** MC_SetCamOnlineChangeMode of a table (`/cam-tables/{table}/online-change-mode`). */
export type OnlineChange = S['OnlineChange'];
export type OnlineActivationMode = S['OnlineActivationMode'];
export type TableType = S['TableType'];
/** Axis groups (TF5420 CM group): the configuration resource, its body, the live status. */
export type GroupResource = S['GroupResource'];
export type GroupBody = S['GroupBody'];
export type GroupStatus = S['GroupStatusDto'];
export type GroupState = S['GroupState'];
export type GroupRole = S['GroupRole'];
export type AxesConvention = S['AxesConvention'];
export type PathDynamics = S['PathDynamics'];
/** MC_MovePath's body and one entry of its table (`type`: linear, circular, blocker, dwell). */
export type MovePathBody = S['MovePathBody'];
export type PathEntry = S['PathEntryDto'];
export type PathValue = S['PathValueDto'];
export type BufferMode = S['BufferMode'];
export type TransitionMode = S['TransitionModeDto'];
export type CircMode = S['CircMode'];
export type CircPathChoice = S['CircPathChoice'];
/** `POST /path-analysis`: a path table planned for a group without running it, and the plan. */
export type PathAnalysisBody = S['PathAnalysisBody'];
export type PathAnalysisResource = S['PathAnalysisResource'];
export type PlannedAxis = S['PlannedAxisDto'];
